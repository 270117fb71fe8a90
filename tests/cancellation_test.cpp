// Ctrl-C and SIGTERM during every long command (issue 11, "Done means"): the command exits
// within 2 s with status 130 / 143 and ONE line on stderr saying it was interrupted, no child
// process (COLMAP) is left, and no output that looks complete (or partial) is left behind.
// Also SIGKILL of arview during COLMAP: the kernel ends COLMAP too (PR_SET_PDEATHSIG).
//
// Inputs are small so that the suite stays quick: one rendered room of 60 frames (made once
// per machine with `arview synth room`, from the opencv-doc photos, kept in the temp folder), and for track/replay a synthetic map
// (random points and descriptors: every frame is lost, but the per-frame loop runs).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "calib/camera.h"
#include "map/map_file.h"
#include "tests/support/random_map.h"
#include "tests/support/run_command.h"
#include "tests/support/spawn_command.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::LineCount;
using testing::ProcessesMentioning;
using testing::SpawnedArview;

constexpr int kRoomFrames = 60;

// The suite's shared inputs, made once.
class Cancellation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("arview_cancel_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    if (!fs::exists("/usr/share/doc/opencv-doc/examples/data/left01.jpg")) return;
    if (!RenderSharedRoom()) return;
    testing::WriteRandomMap(calib::LoadCamera(Room() / "camera.yaml"), SyntheticMap());
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*root_, ec);
    delete root_;
  }

  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH("/usr/share/doc/opencv-doc/examples/data/left01.jpg", "Debian package opencv-doc");
    ASSERT_TRUE(fs::exists(Room() / "frames.txt")) << "the rendered room is missing";
    ASSERT_TRUE(fs::exists(SyntheticMap() / map::kMapFileName)) << "the synthetic map is missing";
  }

  // ctest runs every test in its own process: the room is rendered once per machine and user
  // (rendered under a private name, then renamed into place, so parallel tests never see half
  // of it) and reused by later processes.
  static fs::path Room() {
    return fs::temp_directory_path() / ("arview_cancellation_room_" + std::to_string(::getuid()) + "_" +
                                        std::to_string(kRoomFrames));
  }
  static bool RenderSharedRoom() {
    if (fs::exists(Room() / "frames.txt")) return true;
    const fs::path rendering = *root_ / "room_rendering";
    const auto r = testing::RunArview({"synth", "room", "--out", rendering.string(), "--frames",
                                       std::to_string(kRoomFrames), "--seed", "1", "--quiet"});
    if (r.exit_code != 0) {
      std::fprintf(stderr, "synth room failed: %s\n", r.err.c_str());
      return false;
    }
    std::error_code ec;
    fs::rename(rendering, Room(), ec);  // fails harmlessly when a parallel test got there first
    return fs::exists(Room() / "frames.txt");
  }
  static fs::path SyntheticMap() { return *root_ / "random_map"; }
  // A fresh folder for one test, named after it (so that its processes can be found by name).
  static fs::path Work(const std::string& name) {
    const fs::path dir = *root_ / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
  }

  // Everything issue 11 asks of an interrupted command, given the test's folder (no process
  // may mention it afterwards) and the files that must not exist.
  static void ExpectCleanInterruption(SpawnedArview& run, int signal_number, const fs::path& work,
                                      const std::vector<fs::path>& must_not_exist) {
    const double seconds = run.SignalAndTimeExit(signal_number, std::chrono::seconds(10));
    ASSERT_GE(seconds, 0) << "still running 10 s after the signal";
    EXPECT_LT(seconds, 2.0) << "took " << seconds << " s to stop";
    EXPECT_EQ(run.exit_code(), 128 + signal_number) << run.Stderr();
    const std::string said = run.StderrAfterSignal();
    EXPECT_EQ(LineCount(said), 1) << "after the signal, stderr said:\n" << said;
    EXPECT_NE(said.find("interrupted"), std::string::npos) << said;
    // Children exit before their parent returns; allow the kernel a moment to reap a killed one.
    for (int i = 0; i < 50 && !ProcessesMentioning(work.string()).empty(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    for (const std::string& p : ProcessesMentioning(work.string())) ADD_FAILURE() << "left running: " << p;
    for (const fs::path& f : must_not_exist) EXPECT_FALSE(fs::exists(f)) << f << " was left behind";
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(work, ec)) {
      EXPECT_NE(e.path().extension(), ".tmp") << e.path() << ": a temporary file was left behind";
    }
  }

  // True once a COLMAP process whose command line mentions `work` runs.
  static bool ColmapRunsFor(const fs::path& work) {
    for (const std::string& p : ProcessesMentioning(work.string())) {
      if (p.find("colmap ") != std::string::npos) return true;
    }
    return false;
  }

  static fs::path* root_;
};

fs::path* Cancellation::root_ = nullptr;

class CancellationBySignal : public Cancellation, public ::testing::WithParamInterface<int> {};

std::string SignalLabel(const ::testing::TestParamInfo<int>& info) {
  return info.param == SIGINT ? "Sigint" : "Sigterm";
}

TEST_P(CancellationBySignal, DemoDuringItsColmapStage) {
  const fs::path work = Work("demo_" + SignalLabel({GetParam(), 0}));
  fs::copy(Room(), work / "room", fs::copy_options::recursive | fs::copy_options::create_hard_links);  // the demo reuses a rendered room
  SpawnedArview run({"demo", "--frames", std::to_string(kRoomFrames), "--work", work.string()}, work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return ColmapRunsFor(work); }, std::chrono::seconds(60))) << run.Stderr();
  ExpectCleanInterruption(run, GetParam(), work,
                          {work / "demo.mp4", work / "demo.partial.mp4", work / "trajectory.txt", work / "stats.json",
                           work / "map" / map::kMapFileName});
  run.RemoveLogs();
}

TEST_P(CancellationBySignal, MapDuringColmap) {
  const fs::path work = Work("map_" + SignalLabel({GetParam(), 0}));
  SpawnedArview run({"map", Room().string(), "--out", (work / "map").string(), "--frames", "0-59:4"},
                    work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return ColmapRunsFor(work); }, std::chrono::seconds(30))) << run.Stderr();
  ExpectCleanInterruption(run, GetParam(), work, {work / "map" / map::kMapFileName, work / "map" / "keyframes.txt"});
  run.RemoveLogs();
}

TEST_P(CancellationBySignal, TrackDuringItsFrames) {
  const fs::path work = Work("track_" + SignalLabel({GetParam(), 0}));
  const fs::path out = work / "trajectory.txt", stats = work / "stats.json";
  SpawnedArview run({"track", Room().string(), "--map", SyntheticMap().string(), "--out", out.string(), "--stats",
                     stats.string()},
                    work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return run.Stderr().find("track:") != std::string::npos; }, std::chrono::seconds(60)))
      << run.Stderr();
  ExpectCleanInterruption(run, GetParam(), work, {out, stats});
  run.RemoveLogs();
}

TEST_P(CancellationBySignal, ReplayIntoAVideo) {
  const fs::path work = Work("replay_" + SignalLabel({GetParam(), 0}));
  const fs::path video = work / "out.mp4", trajectory = work / "trajectory.txt", stats = work / "stats.json";
  SpawnedArview run({"replay", Room().string(), "--map", SyntheticMap().string(), "--out", video.string(),
                     "--trajectory", trajectory.string(), "--stats", stats.string()},
                    work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return run.Stderr().find("augmenting frames") != std::string::npos; },
                          std::chrono::seconds(60)))
      << run.Stderr();
  ExpectCleanInterruption(run, GetParam(), work, {video, work / "out.partial.mp4", trajectory, stats});
  run.RemoveLogs();
}

TEST_P(CancellationBySignal, ReplayIntoAPngFolder) {
  const fs::path work = Work("replay_png_" + SignalLabel({GetParam(), 0}));
  const fs::path folder = work / "frames";
  SpawnedArview run({"replay", Room().string(), "--map", SyntheticMap().string(), "--out", folder.string()},
                    work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return run.Stderr().find("augmenting frames") != std::string::npos; },
                          std::chrono::seconds(60)))
      << run.Stderr();
  ExpectCleanInterruption(run, GetParam(), work, {folder, work / "frames.partial"});
  run.RemoveLogs();
}

// Issue 17 §6: a frame deleted while `arview replay` runs. The replay (looping over the room, so
// that the frame is read again after it is gone) stops at that frame with one line naming it;
// the video, trajectory and stats are not left looking complete.
TEST_F(Cancellation, AFrameDeletedMidReplayStopsItWithOneLineNamingTheFrame) {
  const fs::path work = Work("replay_deleted_frame");
  fs::copy(Room(), work / "room", fs::copy_options::recursive | fs::copy_options::create_hard_links);
  const fs::path video = work / "out.mp4", trajectory = work / "trajectory.txt", stats = work / "stats.json";
  SpawnedArview run({"replay", (work / "room").string(), "--map", SyntheticMap().string(), "--out", video.string(),
                     "--trajectory", trajectory.string(), "--stats", stats.string(), "--loop", "1000"},
                    work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return run.Stderr().find("augmenting frames") != std::string::npos; },
                          std::chrono::seconds(60)))
      << run.Stderr();
  const fs::path frame = work / "room" / "frames" / "000030.png";
  ASSERT_TRUE(fs::remove(frame));
  ASSERT_TRUE(run.WaitExit(std::chrono::seconds(60))) << "still running 60 s after a frame was deleted";
  const std::string err = run.Stderr();
  EXPECT_EQ(run.exit_code(), 1) << err;
  size_t error_lines = 0;
  for (size_t at = err.find("arview: "); at != std::string::npos; at = err.find("arview: ", at + 1)) ++error_lines;
  EXPECT_EQ(error_lines, 1u) << err;
  const std::string expected = "arview: " + frame.string() + ": does not exist\n";
  EXPECT_TRUE(err.size() >= expected.size() && err.compare(err.size() - expected.size(), expected.size(), expected) == 0)
      << "the last line should name the deleted frame:\n" << err;
  for (const fs::path& f : {video, work / "out.partial.mp4", trajectory, stats}) {
    EXPECT_FALSE(fs::exists(f)) << f << " was left behind";
  }
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(work, ec)) {
    EXPECT_NE(e.path().extension(), ".tmp") << e.path() << ": a temporary file was left behind";
  }
  run.RemoveLogs();
}

INSTANTIATE_TEST_SUITE_P(Signals, CancellationBySignal, ::testing::Values(SIGINT, SIGTERM), SignalLabel);

// SIGKILL cannot be handled: the kernel must take COLMAP down with arview. A COLMAP that
// prints nothing for a long time (the mapper's bundle adjustment) would not even die of
// SIGPIPE: a silent stand-in for COLMAP shows that only PR_SET_PDEATHSIG ends it.
TEST_F(Cancellation, SigkillDuringMapLeavesNoColmap) {
  const fs::path work = Work("map_sigkill");
  const fs::path fake_colmap = work / "silent-colmap";
  std::ofstream(fake_colmap) << "#!/bin/sh\nwhile :; do sleep 0.2; done\n";
  fs::permissions(fake_colmap, fs::perms::owner_all);
  SpawnedArview run({"map", Room().string(), "--out", (work / "map").string(), "--frames", "0-59:4", "--colmap",
                     fake_colmap.string()},
                    work.string() + "_log");
  ASSERT_TRUE(run.WaitFor([&] { return ColmapRunsFor(work); }, std::chrono::seconds(30))) << run.Stderr();
  run.SignalAndTimeExit(SIGKILL, std::chrono::seconds(5));
  for (int i = 0; i < 50 && !ProcessesMentioning(work.string()).empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const std::vector<std::string> left = ProcessesMentioning(work.string());
  for (const std::string& p : left) ADD_FAILURE() << "left running 1 s after arview was killed: " << p;
  for (const std::string& p : left) ::kill(std::stoi(p), SIGKILL);
  run.RemoveLogs();
}

}  // namespace
}  // namespace arview
