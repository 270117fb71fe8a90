// Any camera on any map (issue 56): a map made with one camera (1280x720, wide, distorted) and a
// walk seen by another (640x480, another focal length and distortion), tracked against the map
// with the walk's own camera, in the tracker and through `arview track` and `replay`.
//
// The scene is the graffiti plane (tracker/test_planar_scene.h), rendered exactly through either
// camera's distortion: `arview synth room` renders undistorted frames only, and mapping it with
// COLMAP takes minutes, where this map is built in a second and its ground truth is exact.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "calib/camera.h"
#include "map/map_file.h"
#include "recordings/recording.h"
#include "tests/support/run_command.h"
#include "tracker/test_planar_scene.h"
#include "tracker/tracker.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using tracker::testing::LookAt;
using tracker::testing::PlanarWorld;

// The camera the map is made with: 1280x720, 85° across, barrel distortion.
calib::Camera MapCamera() {
  calib::Camera c = calib::Camera::Pinhole(1280, 720, 700.0, 700.0, 641.5, 357.0);
  c.dist = {-0.25, 0.08, 0.0005, -0.0003, -0.01};
  return c;
}

// The camera that tracks: 640x480 (another aspect), 56° across, milder distortion of its own.
calib::Camera WalkCamera() {
  calib::Camera c = calib::Camera::Pinhole(640, 480, 600.0, 598.0, 318.0, 243.5);
  c.dist = {-0.12, 0.03, -0.0004, 0.0006, 0.0};
  return c;
}

// 40 views at 10 frames a second along an arc 0.75-0.85 m from the plane.
std::vector<calib::Pose> Walk() {
  std::vector<calib::Pose> poses;
  for (int i = 0; i < 40; ++i) {
    const double a = 0.006 * i;
    poses.push_back(LookAt({-0.12 + a, 0.04 * std::sin(4 * a), -0.85 + 0.1 * a}, {0.02 * std::cos(3 * a), 0, 0}));
  }
  return poses;
}

struct Tracked {
  int localized = 0;
  double rms_centre_error_m = 0;  // over the localized frames
};

Tracked TrackWalk(const map::Map& map, const PlanarWorld& world, const std::vector<calib::Pose>& walk) {
  tracker::Tracker t(map, world.camera());
  Tracked out;
  double squared = 0;
  for (size_t i = 0; i < walk.size(); ++i) {
    const tracker::FrameResult r = t.Track(world.Render(walk[i]), 0.1 * static_cast<double>(i));
    if (r.status == tracker::TrackStatus::kLost) continue;
    ++out.localized;
    squared += (r.pose.Center() - walk[i].Center()).squaredNorm();
  }
  if (out.localized > 0) out.rms_centre_error_m = std::sqrt(squared / out.localized);
  return out;
}

class CrossCamera : public ::testing::Test {
 protected:
  void SetUp() override {
    texture_ = cv::imread(tracker::testing::kGraffitiTexture);
    if (texture_.empty()) GTEST_SKIP() << "needs " << tracker::testing::kGraffitiTexture << " (Debian package opencv-doc)";
    dir_ = fs::temp_directory_path() / ("arview_cross_camera_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  cv::Mat texture_;
  fs::path dir_;
};

TEST_F(CrossCamera, AWalkFromAnotherCameraTracksAsWellAsFromTheMapsOwn) {
  const PlanarWorld mapped(texture_, MapCamera(), 0.0015);
  const map::Map map = mapped.MakeMap(tracker::testing::GraffitiKeyframes(), tracker::SiftExtractor());
  const PlanarWorld walked(texture_, WalkCamera(), 0.0015);
  const std::vector<calib::Pose> walk = Walk();

  const Tracked same = TrackWalk(map, mapped, walk);
  const Tracked other = TrackWalk(map, walked, walk);
  std::printf("same camera: %d/%zu localized, centre error RMS %.2f mm; other camera: %d/%zu, %.2f mm\n",
              same.localized, walk.size(), 1e3 * same.rms_centre_error_m, other.localized, walk.size(),
              1e3 * other.rms_centre_error_m);
  EXPECT_GE(other.localized, std::ceil(0.98 * static_cast<double>(walk.size())));
  EXPECT_EQ(same.localized, static_cast<int>(walk.size())) << "the baseline itself";
  EXPECT_LE(other.rms_centre_error_m, 1.5 * same.rms_centre_error_m);

  // The same frames with the map's camera instead are refused by size, not posed wrongly.
  tracker::Tracker with_map_camera(map);
  const tracker::FrameResult r = with_map_camera.Track(walked.Render(walk[0]), 0);
  EXPECT_EQ(r.status, tracker::TrackStatus::kLost);
  EXPECT_NE(r.reason.find("frame is 640x480, the tracking camera is 1280x720"), std::string::npos) << r.reason;
}

// The commands: a recording with its own calibrated camera.yaml is tracked with it on the map
// (`track`, `replay`); without a calibration of its own, one clear line.
TEST_F(CrossCamera, TrackAndReplayUseTheRecordingsOwnCamera) {
  const PlanarWorld mapped(texture_, MapCamera(), 0.0015);
  const fs::path map_dir = dir_ / "map";
  fs::create_directories(map_dir);
  map::SaveMap(mapped.MakeMap(tracker::testing::GraffitiKeyframes(), tracker::SiftExtractor()), map_dir / map::kMapFileName);

  const PlanarWorld walked(texture_, WalkCamera(), 0.0015);
  const std::vector<calib::Pose> walk = Walk();
  const fs::path rec = dir_ / "rec";
  recordings::PrepareRecordingFolder(rec, false);
  calib::SaveCamera(walked.camera(), rec / "camera.yaml");
  std::vector<recordings::FrameEntry> frames;
  for (size_t i = 0; i < walk.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06zu.png", i);
    ASSERT_TRUE(cv::imwrite((rec / name).string(), walked.Render(walk[i])));
    frames.push_back({0.1 * static_cast<double>(i), name});
  }
  recordings::WriteFramesTxt(rec, frames);

  const fs::path trajectory = dir_ / "track.txt";
  const testing::CommandResult track =
      testing::RunArview({"track", rec.string(), "--map", map_dir.string(), "--out", trajectory.string()});
  ASSERT_EQ(track.exit_code, 0) << track.err;
  EXPECT_NE(track.err.find("note: the recording's camera (640x480, fx 600) differs from the map's (1280x720, fx 700): "
                           "its frames are tracked with their own camera"),
            std::string::npos)
      << track.err;
  std::ifstream in(trajectory);
  std::string line;
  int poses = 0;
  double squared = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, x, y, z;
    ASSERT_TRUE(fields >> t >> x >> y >> z) << line;
    const size_t i = static_cast<size_t>(std::lround(t * 10));
    ASSERT_LT(i, walk.size()) << line;
    squared += (Eigen::Vector3d(x, y, z) - walk[i].Center()).squaredNorm();
    ++poses;
  }
  EXPECT_GE(poses, std::ceil(0.98 * static_cast<double>(walk.size())));
  ASSERT_GT(poses, 0);
  EXPECT_LT(std::sqrt(squared / poses), 0.005) << "metres: the track is in the map's world";

  const testing::CommandResult replay =
      testing::RunArview({"replay", rec.string(), "--map", map_dir.string(), "--out", "null", "--no-figure"});
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  EXPECT_NE(replay.err.find("note: the frames' camera differs from the map's (frames 640x480, the map's camera "
                            "1280x720): they are tracked with their own camera"),
            std::string::npos)
      << replay.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(replay.out, m, std::regex(R"(frames: (\d+) read, (\d+) processed, \d+ dropped, (\d+) localized)")))
      << replay.out;
  EXPECT_EQ(std::stoul(m[2].str()), walk.size()) << replay.out;
  EXPECT_GE(std::stod(m[3].str()), std::ceil(0.98 * static_cast<double>(walk.size()))) << replay.out;

  // Without a calibration of its own, the recording's size must be the map camera's.
  calib::Camera guess = walked.camera();
  guess.calibrated = false;
  calib::SaveCamera(guess, rec / "camera.yaml");
  const testing::CommandResult refused =
      testing::RunArview({"track", rec.string(), "--map", map_dir.string(), "--out", trajectory.string()});
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_EQ(testing::LineCount(refused.err), 1) << refused.err;
  EXPECT_NE(refused.err.find("the recording's camera.yaml is not calibrated"), std::string::npos) << refused.err;
}

}  // namespace
}  // namespace arview
