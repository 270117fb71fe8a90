// `arview map extend` (mapping/map_extend.h): templeRing's 24 even frames mapped (the same map
// TempleMapTest builds and shares under its lock) and extended with 8 odd frames, and the inputs
// an extension refuses before it writes anything.

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include <csignal>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "base/cancellation.h"
#include "base/process.h"
#include "calib/camera.h"
#include "map/map_file.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/map_extend.h"
#include "mapping/test_temple_map.h"
#include "recordings/accuracy.h"
#include "recordings/recording.h"
#include "recordings/trajectory.h"
#include "tests/support/random_map.h"
#include "tests/support/folder_bytes.h"
#include "tests/support/stub_map_folder.h"
#include "tests/support/test_data.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

fs::path ScratchDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("arview_extend_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

using testing::CameraOfSize;
using testing::OneFrameRecording;

std::string ExtendError(const fs::path& map_dir, const recordings::Recording& recording) {
  try {
    ExtendMap(map_dir, recording, {});
  } catch (const map::MapError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FitScaleAndShift, UndoesAScaleAndAShift) {
  const std::vector<Eigen::Vector3d> old_centres{{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {1, 1, 3}};
  std::vector<Eigen::Vector3d> normalised;
  for (const auto& c : old_centres) normalised.push_back(0.25 * c + Eigen::Vector3d(5, -1, 2));
  const Sim3 back = FitScaleAndShift(normalised, old_centres);
  EXPECT_NEAR(back.scale, 4.0, 1e-12);
  for (std::size_t i = 0; i < old_centres.size(); ++i) EXPECT_LT((back(normalised[i]) - old_centres[i]).norm(), 1e-12);
}

TEST(CarryFrameRecord, TakesTheModelsCameraKeyframesPointsAndDescriptorsAndKeepsTheOldFrame) {
  map::Map old_map;
  old_map.camera = CameraOfSize(640, 480);
  old_map.keyframes.resize(2);
  old_map.frame.scale_source = map::ScaleSource::kBoard;  // the old map's frame record
  old_map.frame.z_up = true;
  old_map.frame.how = "a 9x6 board of 25 mm squares";
  old_map.frame.from_colmap.scale = 0.37;
  map::Map model;
  model.camera = CameraOfSize(640, 480);
  model.keyframes.resize(5);
  model.points.resize(7);
  model.descriptors = cv::Mat(3, 128, CV_8U, cv::Scalar(1));
  model.descriptor_point = {0, 1, 2};
  model.descriptor_keyframe = {0, 0, 4};
  const map::Map extended = CarryFrameRecord(old_map, model);
  EXPECT_EQ(extended.keyframes.size(), 5u);
  EXPECT_EQ(extended.points.size(), 7u);
  EXPECT_EQ(extended.descriptors.rows, 3);
  EXPECT_EQ(extended.descriptor_keyframe, model.descriptor_keyframe);
  EXPECT_EQ(extended.frame.scale_source, map::ScaleSource::kBoard);
  EXPECT_TRUE(extended.frame.z_up);
  EXPECT_EQ(extended.frame.how, old_map.frame.how);
  EXPECT_EQ(extended.frame.from_colmap.scale, 0.37);
}

// A venue's map extended: the rooms stay, each old keyframe in its own, the session's in none.
TEST(CarryFrameRecord, TheOldKeyframesKeepTheirRoomsAndTheNewOnesHaveNone) {
  map::Map old_map;
  old_map.camera = CameraOfSize(640, 480);
  old_map.rooms = {"east", "west"};
  old_map.keyframes.resize(2);
  old_map.keyframes[0].name = "east/frames/000006.png";
  old_map.keyframes[0].room = 0;
  old_map.keyframes[1].name = "west/frames/000009.png";
  old_map.keyframes[1].room = 1;
  map::Map model;
  model.camera = old_map.camera;
  model.keyframes.resize(3);
  model.keyframes[0].name = "west/frames/000009.png";  // the model's order, not the map's
  model.keyframes[1].name = "frames/000003.png";       // the new session's
  model.keyframes[2].name = "east/frames/000006.png";
  const map::Map extended = CarryFrameRecord(old_map, model);
  EXPECT_EQ(extended.rooms, old_map.rooms);
  EXPECT_EQ(extended.keyframes[0].room, 1);
  EXPECT_EQ(extended.keyframes[1].room, -1);
  EXPECT_EQ(extended.keyframes[2].room, 0);
}

std::vector<map::Keyframe> FourKeyframes() {
  std::vector<map::Keyframe> keyframes(4);
  const Eigen::Vector3d centres[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.2}, {0.5, 0.5, 1}};
  for (std::uint32_t i = 0; i < 4; ++i) {
    keyframes[i].colmap_image_id = i + 1;
    keyframes[i].pose.q_cw = Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitY()));
    keyframes[i].pose.t_cw = -(keyframes[i].pose.q_cw * centres[i]);
  }
  return keyframes;
}

TEST(MapFileFrameOfModel, IsNothingForTheModelsOwnFrameAndTheMoveOtherwise) {
  const std::vector<map::Keyframe> model = FourKeyframes();
  map::Map file;
  file.keyframes = model;
  EXPECT_FALSE(MapFileFrameOfModel(model, file).has_value());

  Sim3 metric;  // as a map made metric and z-up after COLMAP would be
  metric.scale = 2.5;
  metric.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  metric.t = Eigen::Vector3d(1, -2, 0.5);
  for (map::Keyframe& k : file.keyframes) k.pose = calib::Pose::FromRigid(metric.TransformPose(k.pose.ToRigid()));
  const std::optional<Sim3> found = MapFileFrameOfModel(model, file);
  ASSERT_TRUE(found.has_value());
  EXPECT_NEAR(found->scale, 2.5, 1e-9);
  EXPECT_LT((found->R - metric.R).norm(), 1e-9);
  EXPECT_LT((found->t - metric.t).norm(), 1e-9);

  file.keyframes[2].pose.t_cw += Eigen::Vector3d(0.3, 0, 0);  // no one similarity any more
  EXPECT_THROW(MapFileFrameOfModel(model, file), map::MapError);
}

// Each input an extension cannot use is refused with one message naming it, before anything is
// written into the map folder.
TEST(ExtendMap, RefusesWhatItCannotExtendNamingIt) {
  const fs::path dir = ScratchDir("bad");
  const recordings::Recording recording = OneFrameRecording(dir / "rec", CameraOfSize(640, 480));

  EXPECT_NE(ExtendError(dir / "none", recording).find("none: no such map folder"), std::string::npos);

  fs::create_directories(dir / "empty");
  EXPECT_NE(ExtendError(dir / "empty", recording).find("map.arvmap"), std::string::npos);

  testing::WriteRandomMap(CameraOfSize(640, 480), dir / "no-db");
  EXPECT_NE(ExtendError(dir / "no-db", recording).find("database.db: missing"), std::string::npos);

  testing::WriteRandomMap(CameraOfSize(640, 480), dir / "no-model");
  std::ofstream(dir / "no-model" / "database.db") << "";
  EXPECT_NE(ExtendError(dir / "no-model", recording).find("sparse: no COLMAP model to extend"), std::string::npos);

  // A map with its database and model, and a recording of another camera size.
  testing::WriteStubMapFolder(dir / "map");
  const recordings::Recording small = OneFrameRecording(dir / "small", CameraOfSize(320, 240));
  const std::string size_error = ExtendError(dir / "map", small);
  EXPECT_NE(size_error.find("camera.yaml: the recording's frames are 320x240, the map's camera 640x480"),
            std::string::npos)
      << size_error;
  std::set<std::string> entries;
  for (const auto& e : fs::directory_iterator(dir / "map")) entries.insert(e.path().filename().string());
  EXPECT_EQ(entries, (std::set<std::string>{"database.db", "map.arvmap", "sparse"}));
  fs::remove_all(dir);
}

// Issue 57: what `map extend` found only in COLMAP's stages (a damaged cameras.bin: two stages
// run, then 15 lines of COLMAP's stack trace), or called by the wrong name (a FIFO as "missing"),
// or took (another map's model beside the map file), each named before anything is written.
TEST(ExtendMap, ADamagedModelAFifoDatabaseAndAnotherMapsModelAreNamedBeforeAnyStage) {
  const fs::path dir = ScratchDir("round4");
  const recordings::Recording recording = OneFrameRecording(dir / "rec", CameraOfSize(640, 480));

  testing::WriteStubMapFolder(dir / "cameras");
  const fs::path cameras = dir / "cameras" / "sparse" / "0" / "cameras.bin";
  fs::resize_file(cameras, fs::file_size(cameras) - 9);  // cut inside the camera's parameters
  const auto cut = testing::FolderBytes(dir / "cameras");
  const std::string damaged = ExtendError(dir / "cameras", recording);
  EXPECT_EQ(damaged.rfind(cameras.string() + ": ", 0), 0u) << damaged;
  EXPECT_TRUE(cut == testing::FolderBytes(dir / "cameras")) << "the map folder changed";

  testing::WriteStubMapFolder(dir / "fifo");
  fs::remove(dir / "fifo" / "database.db");
  ASSERT_EQ(::mkfifo((dir / "fifo" / "database.db").c_str(), 0644), 0);
  const std::string fifo = ExtendError(dir / "fifo", recording);
  EXPECT_NE(fifo.find("database.db: is a FIFO"), std::string::npos) << fifo;
  EXPECT_EQ(fifo.find("missing"), std::string::npos) << fifo;

  testing::WriteStubMapFolder(dir / "other");
  map::Map other = map::LoadMap(dir / "other");
  other.keyframes[1].name = "frames/000009.png";  // the map file of another map, the model of this one
  map::SaveMap(other, dir / "other" / map::kMapFileName);
  const auto before = testing::FolderBytes(dir / "other");
  const std::string model = ExtendError(dir / "other", recording);
  EXPECT_NE(model.find((dir / "other" / "sparse" / "0").string() + ": not the COLMAP model of " +
                       (dir / "other" / "map.arvmap").string() +
                       " (COLMAP's image 2 is 'frames/000002.png' there and 'frames/000009.png' in the map)"),
            std::string::npos)
      << model;
  EXPECT_TRUE(before == testing::FolderBytes(dir / "other")) << "the map folder changed";
  fs::remove_all(dir);
}

// The stub folder's database.db made one COLMAP could be asked about: its images table names the
// map's two keyframes, with camera 1.
void WriteStubDatabase(const fs::path& map_dir) {
  fs::remove(map_dir / "database.db");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((map_dir / "database.db").c_str(), &db), SQLITE_OK);
  const char* sql =
      "CREATE TABLE images(image_id INTEGER PRIMARY KEY, name TEXT, camera_id INTEGER);"
      "INSERT INTO images VALUES(1, 'frames/000001.png', 1);INSERT INTO images VALUES(2, 'frames/000002.png', 1);";
  EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
}

// Issue 57: `map extend` twice with the same frames registered them twice (duplicate keyframes).
// Frames whose image is a keyframe's, byte for byte, are skipped with a note; when every frame is,
// the extension is refused before anything runs.
TEST(ExtendMap, FramesTheMapHoldsAlreadyAreSkippedAndAllOfThemRefused) {
  if (FindExecutable("colmap").empty()) GTEST_SKIP() << "needs COLMAP (apt-get install colmap)";
  const fs::path dir = ScratchDir("again");
  const recordings::Recording one = OneFrameRecording(dir / "rec", CameraOfSize(640, 480));
  testing::WriteStubMapFolder(dir / "map");
  WriteStubDatabase(dir / "map");
  // The recording's frame kept as keyframe 2's image, as an extension keeps the frames it adds.
  fs::create_directories(dir / "map" / "images" / "frames");
  fs::copy_file(dir / "rec" / "frames" / "000000.png", dir / "map" / "images" / "frames" / "000002.png");
  const auto before = testing::FolderBytes(dir / "map");
  const std::string all = ExtendError(dir / "map", one);
  EXPECT_NE(all.find("every frame selected from " + (dir / "rec").string() + " is in the map already "
                     "('frames/000000.png' is keyframe 'frames/000002.png'): nothing to add; the map in " +
                     (dir / "map").string() + " is as it was"),
            std::string::npos)
      << all;
  EXPECT_TRUE(before == testing::FolderBytes(dir / "map")) << "the map folder changed";
  EXPECT_FALSE(fs::exists(dir / "map" / kExtendPartialName));

  // A second, new frame: the one in the map is skipped, said in a note; the other goes on to
  // COLMAP (whose extraction fails on the stub's database: not this test's concern).
  cv::imwrite((dir / "rec" / "frames" / "000001.png").string(), cv::Mat(480, 640, CV_8UC3, cv::Scalar(30, 60, 90)));
  recordings::WriteFramesTxt(dir / "rec", {{0.0, "frames/000000.png"}, {0.1, "frames/000001.png"}});
  std::vector<std::string> notes;
  MapBuildCallbacks cb;
  cb.note = [&notes](const std::string& note) { notes.push_back(note); };
  try {
    ExtendMap(dir / "map", recordings::LoadRecording(dir / "rec"), {}, cb);
  } catch (const std::exception&) {
  }
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0], "1 of the 2 frames selected from " + (dir / "rec").string() +
                          " are in the map already ('frames/000000.png' is keyframe 'frames/000002.png'): skipped");
  fs::remove_all(dir);
}

// A copy of the shared map folder while TempleMapTest's processes may be rewriting its files
// (each atomically, through a temporary file beside it): a file gone between listing and copying
// was such a temporary one.
void CopyFolderInUse(const fs::path& from, const fs::path& to) {
  for (const auto& entry : fs::recursive_directory_iterator(from)) {
    const fs::path target = to / fs::relative(entry.path(), from);
    std::error_code ec;
    if (entry.is_directory(ec)) {
      fs::create_directories(target);
      continue;
    }
    fs::create_directories(target.parent_path());
    fs::copy_file(entry.path(), target, fs::copy_options::overwrite_existing, ec);
    if (ec && fs::exists(entry.path())) throw std::runtime_error(entry.path().string() + ": cannot copy: " + ec.message());
  }
}

class ExtendTempleMapTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path source = testing::SharedData("templeRing");
    if (!fs::exists(source)) return;  // each test skips (or fails under ARVIEW_REQUIRE_DATA=1)
    // TempleMapTest's map: whichever suite comes first builds it.
    recording_ = std::make_unique<recordings::Recording>();
    testing::BuildSharedTempleMap(source, recording_.get());
    scratch_ = ScratchDir("temple");
    // The shared map stays as TempleMapTest needs it: each test extends its own copy.
    CopyFolderInUse(testing::TempleMapRoot() / "map", scratch_ / "original");
  }
  static void TearDownTestSuite() {
    if (!scratch_.empty()) fs::remove_all(scratch_);
    recording_.reset();
  }
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("templeRing"), "../shared/data");
    ASSERT_TRUE(recording_) << "building the map failed in SetUpTestSuite";
  }
  static fs::path CopyOfTheMap(const std::string& name) {
    fs::remove_all(scratch_ / name);
    fs::copy(scratch_ / "original", scratch_ / name, fs::copy_options::recursive);
    return scratch_ / name;
  }
  static MapExtendOptions OddFrames() {
    MapExtendOptions options;
    options.build.frames_spec = "1-46:6";  // 8 frames between the map's
    options.old_neighbours = 6;
    return options;
  }

  static fs::path scratch_;
  static std::unique_ptr<recordings::Recording> recording_;
};
fs::path ExtendTempleMapTest::scratch_;
std::unique_ptr<recordings::Recording> ExtendTempleMapTest::recording_;

TEST_F(ExtendTempleMapTest, RegistersTheNewFramesAndKeepsTheOldKeyframesAndTheFrame) {
  const fs::path dir = CopyOfTheMap("extended");
  // The map file in another frame than COLMAP's model, as one made metric and z-up after COLMAP
  // could be: the extension keeps the file's frame.
  map::Map before = map::LoadMap(dir);
  Sim3 moved;
  moved.scale = 3;
  moved.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  moved.t = Eigen::Vector3d(0.5, 4, -1);
  for (map::Keyframe& k : before.keyframes) k.pose = calib::Pose::FromRigid(moved.TransformPose(k.pose.ToRigid()));
  for (map::MapPoint& p : before.points) p.xyz = moved(p.xyz);
  map::SaveMap(before, dir / map::kMapFileName);
  std::map<std::string, std::pair<int, int>> progress;
  MapBuildCallbacks cb;
  cb.progress = [&](const std::string& stage, int done, int total) { progress[stage] = {done, total}; };
  const MapExtendResult r = ExtendMap(dir, *recording_, OddFrames(), cb);

  EXPECT_EQ(r.session, "session-2");
  EXPECT_EQ(r.selected_frames.size(), 8u);
  EXPECT_GE(r.registered, 7);
  EXPECT_EQ(r.old_keyframes_kept, 24);
  EXPECT_GT(r.points_after, r.points_before);
  // The old keyframes' poses were held and COLMAP's normalisation undone: the map's frame.
  EXPECT_LT(r.drift_max, 1e-9 * r.path_extent);
  EXPECT_LT(r.drift_rotation_max_deg, 1e-6);
  EXPECT_NE(r.colmap_shift_scale, 1.0);  // there was a normalisation to undo
  EXPECT_TRUE(r.no_longer_match.empty());
  for (const char* stage : {"extract", "match", "register"}) {
    ASSERT_TRUE(progress.count(stage)) << stage;
    EXPECT_EQ(progress[stage].first, progress[stage].second) << stage;
  }

  // The folder holds the extended map, the same as the result, with the old poses exactly.
  const map::Map after = map::LoadMap(dir);
  EXPECT_EQ(after.keyframes.size(), 24u + static_cast<std::size_t>(r.registered));
  std::map<std::uint32_t, const map::Keyframe*> old_by_id;
  for (const map::Keyframe& k : before.keyframes) old_by_id[k.colmap_image_id] = &k;
  for (const map::Keyframe& k : after.keyframes) {
    const auto it = old_by_id.find(k.colmap_image_id);
    if (it == old_by_id.end()) {
      EXPECT_EQ(k.name.rfind("session-2/", 0), 0u) << k.name;
      EXPECT_TRUE(fs::exists(dir / "images" / k.name)) << k.name;
      continue;
    }
    EXPECT_LT((k.pose.Center() - it->second->pose.Center()).norm(), 1e-9 * r.path_extent) << k.name;
    EXPECT_LT(Eigen::AngleAxisd(k.pose.q_cw.conjugate() * it->second->pose.q_cw).angle(), 1e-9) << k.name;
  }
  // The new keyframes sit where the ground truth says, in the old frame (Sim(3) over all).
  const recordings::Trajectory keyframes = recordings::ReadTum(dir / "keyframes.txt");
  EXPECT_EQ(keyframes.size(), after.keyframes.size());
  const recordings::AccuracyReport report = recordings::EvaluateTrajectory(keyframes, *recording_->groundtruth);
  EXPECT_LE(report.ate.median, 0.002) << recordings::ReportToText(report);
  for (const char* file : {"check.json", "map.png", kExtendRecordName}) EXPECT_TRUE(fs::exists(dir / file)) << file;
  EXPECT_FALSE(fs::exists(dir / kExtendPartialName));
  EXPECT_FALSE(fs::exists(dir / "database.db-wal"));
  // COLMAP's model, database and the map agree: the self-check runs again from the folder.
  EXPECT_EQ(RecheckMap(dir).keyframes, static_cast<int>(after.keyframes.size()));
}

TEST_F(ExtendTempleMapTest, ACancelledExtensionLeavesTheMapAsItWas) {
  const fs::path dir = CopyOfTheMap("cancelled");
  const auto before = testing::FolderBytes(dir);
  MapExtendOptions options = OddFrames();
  MapBuildCallbacks cb;
  // Stopped while COLMAP's mapper is registering the new frames, the longest stage's child.
  cb.progress = [&](const std::string& stage, int, int) {
    if (stage == "register") options.build.cancel.Cancel(SIGINT);
  };
  try {
    ExtendMap(dir, *recording_, options, cb);
    FAIL() << "the extension was not stopped";
  } catch (const CancelledError& e) {
    EXPECT_NE(std::string(e.what()).find("register stage; the map in " + dir.string() + " is as it was"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / kExtendPartialName));
  EXPECT_TRUE(before == testing::FolderBytes(dir)) << "the map folder changed";
}

// Frames of another place (OpenCV's chessboard photos, 640x480 as templeRing) register nowhere:
// one error saying so, and the map as it was.
TEST_F(ExtendTempleMapTest, FramesOfAnotherPlaceAreRefusedAndTheMapStaysAsItWas) {
  const fs::path photos = "/usr/share/doc/opencv-doc/examples/data";
  if (!fs::exists(photos / "left01.jpg")) GTEST_SKIP() << "needs Debian's opencv-doc (" << photos << ")";
  const fs::path dir = CopyOfTheMap("elsewhere");
  const auto before = testing::FolderBytes(dir);
  const fs::path root = scratch_ / "chessboard";
  recordings::PrepareRecordingFolder(root, true);
  calib::SaveCamera(recording_->camera, root / "camera.yaml");
  std::vector<recordings::FrameEntry> frames;
  for (int i = 1; i <= 4; ++i) {
    const std::string name = "frames/0" + std::to_string(i) + ".jpg";
    fs::copy_file(photos / ("left0" + std::to_string(i) + ".jpg"), root / name);
    frames.push_back({static_cast<double>(i), name});
  }
  recordings::WriteFramesTxt(root, frames);
  try {
    MapExtendOptions every_photo;
    every_photo.old_neighbours = 6;
    ExtendMap(dir, recordings::LoadRecording(root), every_photo);
    FAIL() << "frames of another place were added";
  } catch (const map::MapError& e) {
    EXPECT_NE(std::string(e.what()).find("registered none of the 4 new frames"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / kExtendPartialName));
  EXPECT_TRUE(before == testing::FolderBytes(dir)) << "the map folder changed";
}

// A COLMAP stage that fails: its output's last lines and the map's own colmap.log named (the work
// folder's log is moved there), every other file as it was.
TEST_F(ExtendTempleMapTest, AFailingColmapStageNamesTheMapsLogAndLeavesTheMap) {
  const fs::path dir = CopyOfTheMap("failing");
  auto before = testing::FolderBytes(dir);
  const fs::path fake = scratch_ / "colmap_failing_to_match.sh";
  std::ofstream(fake) << "#!/bin/sh\nif [ \"$1\" = matches_importer ]; then echo 'E: the matcher broke'; exit 3; fi\n"
                         "exec colmap \"$@\"\n";
  fs::permissions(fake, fs::perms::owner_all);
  MapExtendOptions options = OddFrames();
  options.build.colmap = fake.string();
  try {
    ExtendMap(dir, *recording_, options);
    FAIL() << "the failing stage was not reported";
  } catch (const ColmapStageError& e) {
    EXPECT_EQ(e.stage, "match");
    EXPECT_EQ(e.log, dir / "colmap.log");
    EXPECT_NE(std::string(e.what()).find("its output is in " + (dir / "colmap.log").string()), std::string::npos)
        << e.what();
    ASSERT_FALSE(e.log_tail.empty());
    EXPECT_EQ(e.log_tail.back(), "E: the matcher broke");
  }
  auto after = testing::FolderBytes(dir);
  EXPECT_NE(after["colmap.log"].find("E: the matcher broke"), std::string::npos);
  before.erase("colmap.log");
  after.erase("colmap.log");
  EXPECT_TRUE(before == after) << "the map folder changed";
  EXPECT_FALSE(fs::exists(dir / kExtendPartialName));
}

}  // namespace
}  // namespace arview::mapping
