// Issue 17's faults and bad values met through the `arview` binary: a --base-clip the asset
// lacks, degenerate ground truth in `eval`, and every writer on a full disk and in a folder it
// cannot write to (one line naming the file, a non-zero exit, nothing left that looks written).

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <utility>
#include <algorithm>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "map/map_file.h"
#include "tests/support/run_command.h"
#include "tests/support/spawn_command.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::LineCount;
using testing::RunArview;
using testing::ShellQuote;

class Faults : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arview_faults_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  void WriteText(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

  // A 3-frame rendered room at 160x120, and RandomMap with its camera (every frame is
  // relocalized against it and fails: the commands still write their outputs). Skips the test
  // without the room's photos: the caller returns when IsSkipped() or HasFatalFailure().
  void RenderTinyRoomAndRandomMap(fs::path* room, fs::path* map) {
    ARVIEW_REQUIRE_DATA_PATH("/usr/share/doc/opencv-doc/examples/data/left01.jpg", "Debian package opencv-doc");
    *room = dir_ / "room";
    const auto rendered = RunArview({"synth", "room", "--out", room->string(), "--frames", "3", "--size", "160x120", "--quiet"});
    ASSERT_EQ(rendered.exit_code, 0) << rendered.err;
    *map = RandomMap(calib::LoadCamera(*room / "camera.yaml"));
  }

  // A TUM trajectory of `n` poses 1/30 s apart; `moving` spreads the centres over a circle.
  std::string Trajectory(int n, bool moving) {
    std::string text;
    for (int i = 0; i < n; ++i) {
      const double a = 0.3 * i;
      char line[160];
      std::snprintf(line, sizeof line, "%.6f %.4f %.4f %.4f 0 0 0 1\n", i / 30.0, moving ? std::cos(a) : 1.5,
                    moving ? std::sin(a) : -2.0, moving ? 0.1 * i : 0.25);
      text += line;
    }
    return text;
  }

  // 200 random points seen by two keyframes: a valid map that places a character.
  fs::path RandomMap(const calib::Camera& camera = calib::Camera::Pinhole(320, 240, 300, 300, 159.5, 119.5)) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    map::Map map;
    map.camera = camera;
    for (int k = 0; k < 2; ++k) {
      map::Keyframe kf;
      kf.colmap_image_id = static_cast<std::uint32_t>(k + 1);
      kf.name = "frames/" + std::to_string(k) + ".png";
      kf.frame_index = k;
      kf.timestamp = k / 30.0;
      kf.pose.t_cw = Eigen::Vector3d(0.2 * k, 0, 0);
      map.keyframes.push_back(kf);
    }
    const int points = 200;
    map.descriptors = cv::Mat(points, 128, CV_8U);
    cv::randu(map.descriptors, 0, 255);
    for (int i = 0; i < points; ++i) {
      map::MapPoint p;
      // A floor: y = 1 below the cameras, so the dominant plane is found.
      p.xyz = Eigen::Vector3d(coord(rng), 1.0 + 0.001 * coord(rng), 3.0 + coord(rng));
      p.first_descriptor = static_cast<std::uint32_t>(i);
      p.descriptor_count = 1;
      map.points.push_back(p);
      map.descriptor_point.push_back(static_cast<std::uint32_t>(i));
      const std::uint32_t k = static_cast<std::uint32_t>(i % 2);
      map.descriptor_keyframe.push_back(k);
      map::KeyframeObservation o;
      o.point = static_cast<std::uint32_t>(i);
      o.descriptor = static_cast<std::uint32_t>(i);
      o.pixel = map.camera.Project(map.keyframes[k].pose.ToCamera(p.xyz)).cast<float>();
      map.keyframes[k].observations.push_back(o);
    }
    const fs::path folder = dir_ / "map";
    fs::create_directories(folder);
    map::SaveMap(map, folder / map::kMapFileName);
    return folder;
  }

  // Runs arview with a file-size limit of 0: every write() to a regular file fails with EFBIG,
  // as on a full disk (SIGXFSZ is ignored, so that write() returns the error instead of the
  // signal killing the process). stderr goes through a pipe to a process without the limit.
  // `limit_blocks` (512 bytes each) above 0 leaves room for small files only. `preload`: a
  // library preloaded into arview (the fake camera), ASan told not to mind it coming first.
  CommandResult RunOnFullDisk(const std::vector<std::string>& args, int limit_blocks = 0, const std::string& preload = "") {
    const char* bin = std::getenv("ARVIEW_BIN");
    std::string inner = "trap '' XFSZ; ulimit -f " + std::to_string(limit_blocks) + "; ";
    if (!preload.empty()) {
      inner += "LD_PRELOAD=" + ShellQuote(preload) + " ASAN_OPTIONS=\"$ASAN_OPTIONS:verify_asan_link_order=0\" ";
    }
    inner += "exec " + ShellQuote(bin ? bin : "arview");
    for (const auto& a : args) inner += " " + ShellQuote(a);
    const fs::path err = dir_ / "full_disk.err", code = dir_ / "full_disk.code";
    const std::string cmd = "{ sh -c " + ShellQuote(inner) + "; echo $? >" + ShellQuote(code.string()) +
                            "; } 2>&1 >/dev/null </dev/null | cat >" + ShellQuote(err.string());
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    CommandResult r;
    r.exit_code = std::stoi(testing::ReadWholeFile(code.string()));
    r.err = testing::ReadWholeFile(err.string());
    fs::remove(err);
    fs::remove(code);
    return r;
  }

  // The files (not folders) under `folder`: a recording folder left with an empty frames/ and
  // no frames.txt is not a recording; any file would be something left looking written.
  static std::vector<std::string> FilesIn(const fs::path& folder) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(folder, ec)) {
      if (!e.is_directory()) names.push_back(e.path().string());
    }
    return names;
  }

  fs::path dir_;
};

// Issue 17: `arview place --base-clip Nope` wrote a scene naming a clip the asset lacks.
TEST_F(Faults, PlaceRefusesABaseClipTheAssetLacksNamingItsClips) {
  const fs::path map = RandomMap();
  const fs::path scene = dir_ / "scene.yaml";
  const auto r = RunArview({"place", map.string(), "--character", "builtin:figure", "--base-clip", "Nope", "--out",
                            scene.string(), "--no-light"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(LineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("'Nope'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("builtin:figure"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(clips: "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scene));
}

// Issue 17: ground truth with every camera centre at one point made `eval` print numbers; then
// the degenerate alignment's error did not name the file.
TEST_F(Faults, EvalOnDegenerateGroundTruthIsOneErrorNamingTheFile) {
  const fs::path estimate = dir_ / "estimate.txt", groundtruth = dir_ / "groundtruth.txt";
  WriteText(estimate, Trajectory(30, true));
  WriteText(groundtruth, Trajectory(30, false));
  for (const char* align : {"sim3", "se3"}) {
    const auto r = RunArview({"eval", estimate.string(), groundtruth.string(), "--align", align});
    EXPECT_NE(r.exit_code, 0) << align;
    EXPECT_EQ(r.out, "") << align;
    EXPECT_EQ(LineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(groundtruth.string() + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("degenerate"), std::string::npos) << r.err;
  }
  // The estimate degenerate: it is the one named.
  const auto r = RunArview({"eval", groundtruth.string(), estimate.string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.err.find(estimate.string() + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(groundtruth.string() + ": "), std::string::npos) << r.err;
  // Without an alignment nothing needs the spread: the figures are printed.
  EXPECT_EQ(RunArview({"eval", estimate.string(), groundtruth.string(), "--align", "none"}).exit_code, 0);
}

// Every writer on a full disk: one line naming the file, non-zero exit, no file and no
// temporary left. (Issue 17: `track --out` on a full disk exited 0 leaving a 0-byte file;
// place, replay --stats and map left .tmp files.)
TEST_F(Faults, EveryWriterOnAFullDiskFailsWithOneLineAndLeavesNothing) {
  const fs::path map = RandomMap();
  const fs::path estimate = dir_ / "estimate.txt", groundtruth = dir_ / "groundtruth.txt";
  WriteText(estimate, Trajectory(30, true));
  WriteText(groundtruth, Trajectory(30, true));
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  struct Writer {
    std::vector<std::string> args;
    std::string named;  // the file the line must name
  };
  const std::vector<Writer> writers = {
      {{"place", map.string(), "--character", "builtin:figure", "--out", (out / "scene.yaml").string(), "--no-light"},
       (out / "scene.yaml").string()},
      {{"eval", estimate.string(), groundtruth.string(), "--plot", (out / "plot.png").string()},
       (out / "plot.png").string()},
      {{"synth", "room", "--out", (out / "room").string(), "--frames", "2", "--size", "160x120", "--quiet"},
       (out / "room").string()},
  };
  for (const auto& w : writers) {
    const auto r = RunOnFullDisk(w.args);
    EXPECT_NE(r.exit_code, 0) << w.args[0] << ": " << r.err;
    EXPECT_EQ(LineCount(r.err), 1) << w.args[0] << ": " << r.err;
    EXPECT_NE(r.err.find(w.named), std::string::npos) << w.args[0] << ": " << r.err;
    const auto left = FilesIn(out);
    EXPECT_TRUE(left.empty()) << w.args[0] << " left " << left.front();
    fs::remove_all(out);
    fs::create_directories(out);
  }
}

// Issue 17's data loss: `track --out t.txt` on a full filesystem exited 0, printed
// "trajectory: .../t.txt" and left a 0-byte file. A 3-frame rendered room and a random map
// with its camera (every frame is relocalized and fails; the trajectory file is still written).
TEST_F(Faults, TrackOnAFullDiskFailsAndLeavesNoTrajectoryOrStats) {
  fs::path room, map;
  RenderTinyRoomAndRandomMap(&room, &map);
  if (IsSkipped() || HasFatalFailure()) return;
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  const std::vector<std::string> args = {"track", room.string(), "--map", map.string(), "--out",
                                         (out / "t.txt").string(), "--stats", (out / "stats.json").string()};
  ASSERT_EQ(RunArview(args).exit_code, 0) << "track must work with room to write";
  fs::remove_all(out);
  fs::create_directories(out);
  const auto r = RunOnFullDisk(args);
  EXPECT_NE(r.exit_code, 0) << r.err;
  // The progress lines ("track: 3/3 (100%) lost") come first; then one error line.
  const size_t last_line = r.err.rfind('\n', r.err.size() - 2);
  const std::string error = r.err.substr(last_line == std::string::npos ? 0 : last_line + 1);
  EXPECT_EQ(error.rfind("arview: " + out.string(), 0), 0u) << r.err;
  EXPECT_EQ(r.err.find("arview: "), r.err.rfind("arview: ")) << r.err;
  const auto left = FilesIn(out);
  EXPECT_TRUE(left.empty()) << "left " << left.front();
}

// The last `arview:` line of stderr (progress lines come first), and how many there are.
std::pair<std::string, size_t> ErrorLines(const std::string& err) {
  size_t count = 0, last = std::string::npos;
  for (size_t at = 0; at < err.size();) {
    const size_t end = std::min(err.find('\n', at), err.size());
    if (err.compare(at, 8, "arview: ") == 0) {
      ++count;
      last = at;
    }
    at = end + 1;
  }
  if (last == std::string::npos) return {"", 0};
  return {err.substr(last, std::min(err.find('\n', last), err.size()) - last), count};
}

// Issue 17 §6, the writers the first full-disk test left out: replay into a video (with
// --trajectory and --stats), into a PNG folder, and --stats alone; import of an image folder;
// calibrate with --report. A 3-frame rendered room and a random map with its camera, as above.
TEST_F(Faults, ReplayImportAndCalibrateOnAFullDiskFailWithOneLineAndLeaveNothing) {
  const fs::path photos = "/usr/share/doc/opencv-doc/examples/data";
  ARVIEW_REQUIRE_DATA_PATH(photos / "left01.jpg", "Debian package opencv-doc");
  fs::path room, map;
  RenderTinyRoomAndRandomMap(&room, &map);
  if (IsSkipped() || HasFatalFailure()) return;
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  const std::string chessboards = (photos / "left0[1-6].jpg").string();
  struct Writer {
    std::string name;
    std::vector<std::string> args;
  };
  const std::vector<Writer> writers = {
      {"replay into a video", {"replay", room.string(), "--map", map.string(), "--out", (out / "v.mp4").string(),
                               "--trajectory", (out / "t.txt").string(), "--stats", (out / "s.json").string()}},
      {"replay into a PNG folder", {"replay", room.string(), "--map", map.string(), "--out", (out / "frames").string()}},
      {"replay --stats", {"replay", room.string(), "--map", map.string(), "--out", "null", "--stats",
                          (out / "s.json").string()}},
      {"import images", {"import", "images", (room / "frames").string(), "--camera", (room / "camera.yaml").string(),
                         "--out", (out / "imported").string()}},
      {"calibrate", {"calibrate", "--images", chessboards, "--out", (out / "camera.yaml").string(), "--report",
                     (out / "report.png").string()}},
  };
  for (const auto& w : writers) {
    // Each must work with room to write: the failure below is the full disk's.
    const auto ok = RunArview(w.args);
    ASSERT_EQ(ok.exit_code, 0) << w.name << ": " << ok.err;
    ASSERT_FALSE(FilesIn(out).empty()) << w.name << " wrote nothing";
    fs::remove_all(out);
    fs::create_directories(out);
    const auto r = RunOnFullDisk(w.args);
    EXPECT_NE(r.exit_code, 0) << w.name << ": " << r.err;
    const auto [error, count] = ErrorLines(r.err);
    EXPECT_EQ(count, 1u) << w.name << ": " << r.err;
    EXPECT_EQ(error.rfind("arview: " + out.string(), 0), 0u) << w.name << ": " << r.err;
    EXPECT_NE(error.find("File too large"), std::string::npos) << w.name << ": " << r.err;
    const auto left = FilesIn(out);
    EXPECT_TRUE(left.empty()) << w.name << " left " << left.front();
    fs::remove_all(out);
    fs::create_directories(out);
  }
}

// Issue 17 §6 for `arview map`, on a full disk from the start (its first write, the image list,
// failed as "cannot write" without the reason and left the list empty) and on a disk with room
// for small files only, where COLMAP's database cannot grow: COLMAP printed a dozen "SQLite
// error ...: disk I/O error" lines (echoed as the last lines of its output) and arview said only
// that it exited with code 1, leaving the half-made database. Now one line with the cause; no
// map file, no temporary, no database, no stage recorded as finished (a re-run redoes it).
TEST_F(Faults, MapOnAFullDiskFailsWithOneLineAndLeavesNoMap) {
  fs::path room, unused_map;
  RenderTinyRoomAndRandomMap(&room, &unused_map);
  if (IsSkipped() || HasFatalFailure()) return;
  const fs::path out = dir_ / "out";
  for (int limit_blocks : {0, 8}) {  // nothing, or 4 KiB a file
    fs::create_directories(out);
    const auto r = RunOnFullDisk({"map", room.string(), "--out", (out / "map").string()}, limit_blocks);
    const std::string label = "limit " + std::to_string(limit_blocks) + ": ";
    EXPECT_NE(r.exit_code, 0) << label << r.err;
    const auto [error, count] = ErrorLines(r.err);
    EXPECT_EQ(count, 1u) << label << r.err;
    EXPECT_EQ(error.rfind("arview: " + out.string(), 0), 0u) << label << r.err;
    EXPECT_NE(error.find("File too large"), std::string::npos) << label << r.err;
    EXPECT_EQ(r.err.find("  | "), std::string::npos) << label << "COLMAP's lines echoed: " << r.err;
    for (const std::string& file : FilesIn(out)) {
      EXPECT_NE(fs::path(file).filename().string(), std::string(map::kMapFileName)) << label << "left the map file";
      EXPECT_EQ(file.find(".tmp"), std::string::npos) << label << "left " << file;
      EXPECT_NE(fs::path(file).extension(), ".inputs") << label << "recorded a stage as finished: " << file;
      EXPECT_EQ(file.find("database.db"), std::string::npos) << label << "left COLMAP's half-made database: " << file;
    }
    if (limit_blocks == 0) {
      const auto left = FilesIn(out);
      EXPECT_TRUE(left.empty()) << label << "left " << left.front();
    }
    fs::remove_all(out);
  }
}

// Issue 17 §6 for `arview record`, end to end: the binary records a camera preloaded into it
// (tests/support/fake_v4l2_device.cpp: 64x48 YUYV at about 30 frames a second, 195-byte PNGs).
// On a full disk from the start it left an empty frames.txt and frames/, a recording of nothing;
// on a disk that fills part-way (a 1 KiB file-size limit: frames.txt fills after about 33
// frames) its error was glued to the end of the progress line and did not say what was kept.
// Now one `arview:` line on a line of its own; nothing left, or a valid recording of the frames
// before, as the line says.
TEST_F(Faults, RecordOnAFullDiskFailsWithOneLineAndKeepsOnlyAValidRecording) {
  const std::string camera = ARVIEW_FAKE_V4L2_LIBRARY;  // built beside the tests (tests/CMakeLists.txt)
  ASSERT_TRUE(fs::exists(camera)) << camera;
  const fs::path recording = dir_ / "out" / "rec";
  fs::create_directories(recording.parent_path());
  const std::vector<std::string> args = {"record", "--device", "/dev/video-arview-fake", "--out", recording.string(),
                                         "--size", "64x48", "--seconds", "3"};
  for (int limit_blocks : {0, 2}) {
    const std::string label = "limit " + std::to_string(limit_blocks) + ": ";
    const auto r = RunOnFullDisk(args, limit_blocks, camera);
    EXPECT_NE(r.exit_code, 0) << label << r.err;
    const auto [error, count] = ErrorLines(r.err);
    EXPECT_EQ(count, 1u) << label << r.err;
    EXPECT_EQ(error.rfind("arview: " + recording.string() + "/frames.txt: cannot write", 0), 0u) << label << r.err;
    for (const std::string& file : FilesIn(recording.parent_path())) {
      EXPECT_EQ(file.find(".tmp"), std::string::npos) << label << "left " << file;
    }
    if (limit_blocks == 0) {
      EXPECT_NE(error.find("File too large"), std::string::npos) << label << r.err;
      EXPECT_FALSE(fs::exists(recording)) << label << "left a recording of nothing";
      fs::remove_all(recording);
      continue;
    }
    EXPECT_NE(error.find("frames recorded before stay a valid recording in " + recording.string()), std::string::npos)
        << label << r.err;
    // Valid: every line after the header names a frame that is there, and every frame is named.
    std::ifstream list(recording / "frames.txt");
    std::string line;
    std::getline(list, line);
    size_t frames = 0;
    while (std::getline(list, line)) {
      ++frames;
      const std::string path = line.substr(line.find(' ') + 1);
      EXPECT_TRUE(fs::is_regular_file(recording / path)) << label << line;
    }
    EXPECT_GT(frames, 0u) << label;
    EXPECT_EQ(frames, FilesIn(recording / "frames").size()) << label;
    fs::remove_all(recording);
  }
}

// The same writers into a folder that cannot be written: a read-only tmpfs (permission bits do
// not stop root, who runs CI here; without the right to mount, a folder without write
// permission when not root).
TEST_F(Faults, EveryWriterIntoAnUnwritableFolderFailsWithOneLine) {
  const fs::path map = RandomMap();
  const fs::path estimate = dir_ / "estimate.txt", groundtruth = dir_ / "groundtruth.txt";
  WriteText(estimate, Trajectory(30, true));
  WriteText(groundtruth, Trajectory(30, true));
  const fs::path out = dir_ / "readonly";
  fs::create_directories(out);
  bool mounted = ::mount("tmpfs", out.c_str(), "tmpfs", MS_RDONLY, "size=64k") == 0;
  if (!mounted) {
    if (::geteuid() == 0) GTEST_SKIP() << "running as root without the right to mount a read-only tmpfs";
    fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec);
  }
  const std::vector<std::pair<std::vector<std::string>, std::string>> writers = {
      {{"place", map.string(), "--character", "builtin:figure", "--out", (out / "scene.yaml").string(), "--no-light"},
       (out / "scene.yaml").string()},
      {{"eval", estimate.string(), groundtruth.string(), "--plot", (out / "plot.png").string()},
       (out / "plot.png").string()},
  };
  for (const auto& [args, named] : writers) {
    const auto r = RunArview(args);
    EXPECT_NE(r.exit_code, 0) << args[0] << ": " << r.err;
    EXPECT_EQ(LineCount(r.err), 1) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << args[0] << ": " << r.err;
  }
  if (mounted) {
    ::umount(out.c_str());
  } else {
    fs::permissions(out, fs::perms::owner_all);
  }
}

// Issue 17 §3, "only regular files opened as data": a FIFO named as a trajectory (`eval`), as
// the map file (`map info`, `track`) or as a Middlebury camera file (`import`) made arview wait
// for a writer for ever; a map file that links to /dev/zero read as an empty, "truncated" map; a
// FIFO or /dev/zero given to `import video` or as a TUM folder's rgb.txt was "missing".
// Each is now refused at once: one line naming the file and saying what it is.
TEST_F(Faults, AFifoOrADeviceGivenAsADataFileIsRefusedAtOnce) {
  const fs::path fifo_map = dir_ / "fifo_map", zero_map = dir_ / "zero_map", middlebury = dir_ / "middlebury";
  for (const fs::path& d : {fifo_map, zero_map, middlebury}) fs::create_directories(d);
  const fs::path estimate = dir_ / "estimate.txt", groundtruth = dir_ / "groundtruth.txt";
  ASSERT_EQ(::mkfifo(estimate.c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((fifo_map / map::kMapFileName).c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", zero_map / map::kMapFileName);
  ASSERT_EQ(::mkfifo((middlebury / "temple_par.txt").c_str(), 0600), 0);
  WriteText(groundtruth, Trajectory(10, true));
  const fs::path tum = dir_ / "tum", video = dir_ / "walk.mp4", camera = dir_ / "camera.yaml";
  fs::create_directories(tum);
  ASSERT_EQ(::mkfifo((tum / "rgb.txt").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(video.c_str(), 0600), 0);
  calib::SaveCamera(calib::Camera::Pinhole(320, 240, 300, 300, 159.5, 119.5), camera);

  struct Case {
    std::vector<std::string> args;
    fs::path file;
    std::string kind;
  };
  const std::vector<Case> cases = {
      {{"eval", estimate.string(), groundtruth.string()}, estimate, "a FIFO"},
      {{"eval", groundtruth.string(), "/dev/zero"}, "/dev/zero", "a character device"},
      {{"map", "info", fifo_map.string()}, fifo_map / map::kMapFileName, "a FIFO"},
      {{"map", "info", zero_map.string()}, zero_map / map::kMapFileName, "a character device"},
      {{"import", "middlebury", middlebury.string(), "--out", (dir_ / "imported").string()},
       middlebury / "temple_par.txt", "a FIFO"},
      {{"import", "tum", tum.string(), "--out", (dir_ / "imported").string()}, tum / "rgb.txt", "a FIFO"},
      {{"import", "video", video.string(), "--out", (dir_ / "imported").string(), "--camera", camera.string()},
       video, "a FIFO"},
      {{"import", "video", "/dev/zero", "--out", (dir_ / "imported").string(), "--camera", camera.string()},
       "/dev/zero", "a character device"},
  };
  for (const Case& c : cases) {
    const std::string label = c.args[0] + " " + c.args[1] + ": ";
    testing::SpawnedArview run(c.args, dir_ / "fifo_run");
    ASSERT_TRUE(run.WaitExit(std::chrono::seconds(30))) << label << "still waiting after 30 s";
    const std::string err = run.Stderr();
    EXPECT_EQ(run.exit_code(), 1) << label << err;
    EXPECT_EQ(LineCount(err), 1) << label << err;
    EXPECT_EQ(err.rfind("arview: " + c.file.string() + ": is " + c.kind + ", not a data file", 0), 0u) << label << err;
    EXPECT_FALSE(fs::exists(dir_ / "imported" / "frames.txt")) << label;
    run.RemoveLogs();
  }
}

// Issue 17 §6, /dev/full as the output: every writer writes a temporary beside the output and
// renames it over the output, so `eval --plot /dev/full` (as root) replaced the device node with
// a regular file. An output path that exists must now be a regular file (a folder for folder
// outputs): a device, a FIFO, a socket is refused with one line and left as it was. A character
// device like /dev/full (1, 7) is made in the test's folder (root only), never the real one.
TEST_F(Faults, AnOutputThatIsADeviceOrAFifoIsRefusedAndLeftAsItWas) {
  const fs::path estimate = dir_ / "estimate.txt";
  WriteText(estimate, Trajectory(30, true));
  const fs::path fifo = dir_ / "plot_fifo.png", device = dir_ / "full_device.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::vector<std::pair<fs::path, std::string>> outputs = {{fifo, "a FIFO"}};
  if (::mknod(device.c_str(), S_IFCHR | 0600, makedev(1, 7)) == 0) outputs.push_back({device, "a character device"});
  for (const auto& [output, kind] : outputs) {
    const auto r = RunArview({"eval", estimate.string(), estimate.string(), "--plot", output.string()});
    EXPECT_NE(r.exit_code, 0) << output;
    EXPECT_EQ(LineCount(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("arview: " + output.string() + ": is " + kind + ", not a file arview may replace", 0), 0u)
        << r.err;
    struct stat st {};
    ASSERT_EQ(::stat(output.c_str(), &st), 0) << output << " is gone";
    EXPECT_FALSE(S_ISREG(st.st_mode)) << output << " was replaced by a regular file";
  }
  for (const std::string& file : FilesIn(dir_)) EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
}

}  // namespace
}  // namespace arview
