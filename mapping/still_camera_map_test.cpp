// Issue 17's "map that cannot be right": a camera that never moves, filming an object moved in
// front of it. COLMAP reconstructs the object and calls its motion the camera path; arview map
// must say so. The frames are made here: a photo as the still background, another photo as a card
// that turns and slides in front of it, covering about half the picture (projected through the camera, so that COLMAP sees a
// rigid motion), sensor noise on every frame.
//
// The map is built once per machine in $TMPDIR/arview_still_camera_map_<uid> (under a lock, as
// TempleMapTest does): a re-run skips COLMAP's stages and only checks.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <iostream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include "calib/camera.h"
#include "mapping/colmap_pipeline.h"
#include "map/map_file.h"
#include "mapping/map_check.h"
#include "recordings/recording.h"
#include "tests/support/test_data.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

const fs::path kPhotos = "/usr/share/doc/opencv-doc/examples/data";
constexpr int kWidth = 640, kHeight = 480, kFrames = 24;

// The card's corners (0.8 x 0.6 units, graf1.png's aspect) at time index i: turning about the
// vertical axis from -30 to +30 degrees and sliding sideways, 1.4 units in front of the camera
// (about half the picture, as an object held up to a camera).
std::vector<cv::Point2f> CardCorners(const calib::Camera& camera, int i) {
  const double s = static_cast<double>(i) / (kFrames - 1);
  const Eigen::AngleAxisd turn((-30 + 60 * s) * M_PI / 180, Eigen::Vector3d::UnitY());
  const Eigen::AngleAxisd tilt((10 - 20 * s) * M_PI / 180, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d centre(-0.15 + 0.3 * s, 0.03 * std::sin(6 * s), 1.4);
  std::vector<cv::Point2f> corners;
  for (const auto& [x, y] : {std::pair{-0.4, -0.3}, {0.4, -0.3}, {0.4, 0.3}, {-0.4, 0.3}}) {
    const Eigen::Vector3d p = centre + (turn * tilt) * Eigen::Vector3d(x, y, 0);
    const Eigen::Vector2d px = camera.Project(p);
    corners.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
  }
  return corners;
}

void MakeRecording(const fs::path& root, const calib::Camera& camera) {
  recordings::PrepareRecordingFolder(root, true);
  cv::Mat background = cv::imread((kPhotos / "building.jpg").string(), cv::IMREAD_COLOR);
  cv::Mat card = cv::imread((kPhotos / "graf1.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(background.empty());
  ASSERT_FALSE(card.empty());
  cv::resize(background, background, {kWidth, kHeight}, 0, 0, cv::INTER_AREA);
  // A room's wall rather than a facade: softened and dimmed, so that the card holds most of the
  // features (with a facade's, COLMAP finds no initial pair and arview map already fails).
  cv::GaussianBlur(background, background, {0, 0}, 3);
  background.convertTo(background, -1, 0.6, 60);
  const std::vector<cv::Point2f> card_corners{{0, 0},
                                              {static_cast<float>(card.cols), 0},
                                              {static_cast<float>(card.cols), static_cast<float>(card.rows)},
                                              {0, static_cast<float>(card.rows)}};
  cv::RNG rng(17);
  std::vector<recordings::FrameEntry> frames;
  for (int i = 0; i < kFrames; ++i) {
    const cv::Mat h = cv::getPerspectiveTransform(card_corners, CardCorners(camera, i));
    cv::Mat warped, mask;
    cv::warpPerspective(card, warped, h, background.size(), cv::INTER_LINEAR);
    cv::warpPerspective(cv::Mat(card.size(), CV_8UC1, cv::Scalar(255)), mask, h, background.size(), cv::INTER_NEAREST);
    cv::Mat frame = background.clone();
    warped.copyTo(frame, mask);
    cv::Mat noise(frame.size(), CV_16SC3);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2);
    frame.convertTo(frame, CV_16SC3);
    frame += noise;
    frame.convertTo(frame, CV_8UC3);
    const std::string rel = "frames/" + std::to_string(i) + ".png";
    ASSERT_TRUE(cv::imwrite((root / rel).string(), frame));
    frames.push_back({i / 10.0, rel});
  }
  calib::SaveCamera(camera, root / "camera.yaml");
  recordings::WriteFramesTxt(root, frames);
}

TEST(StillCameraMap, AnObjectMovedInFrontOfAStillCameraIsFlagged) {
  ARVIEW_REQUIRE_DATA_PATH(kPhotos / "graf1.png", "Debian package opencv-doc");
  const fs::path root = fs::temp_directory_path() / ("arview_still_camera_map_" + std::to_string(::getuid()));
  fs::create_directories(root);
  const int lock = ::open((root / "lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  ASSERT_GE(lock, 0);
  ::flock(lock, LOCK_EX);
  struct Unlock {
    int fd;
    ~Unlock() { ::close(fd); }
  } unlock{lock};
  const calib::Camera camera = calib::Camera::Pinhole(kWidth, kHeight, 560, 560, 319.5, 239.5);
  if (!fs::exists(root / "recording" / "frames.txt")) {
    MakeRecording(root / "recording", camera);
    if (HasFatalFailure()) return;
  }
  const recordings::Recording recording = recordings::LoadRecording(root / "recording");
  MapBuildOptions options;
  options.UseFastPreset();
  options.matcher = MatcherKind::kExhaustive;
  std::vector<std::string> warnings;
  MapBuildCallbacks callbacks;
  callbacks.warning = [&](const std::string& w) { warnings.push_back(w); };
  // COLMAP does build a model of it (the failure the issue describes). On this sequence some of
  // its registrations are degenerate (keyframes 1e11 units away, measured 2026-12-02): then the
  // map is refused, naming COLMAP's file; otherwise it is written. Either way the check runs
  // first and says why.
  std::string refused;
  try {
    const MapBuildResult result = BuildMap(recording, root / "map", options, callbacks);
    std::cout << "[still camera] registered " << result.map.keyframes.size() << " of " << kFrames << "\n";
    EXPECT_GE(result.map.keyframes.size(), static_cast<std::size_t>(kFrames / 2));
  } catch (const map::MapError& e) {
    refused = e.what();
    std::cout << "[still camera] refused: " << refused << "\n";
    // Reported against the COLMAP file that holds the value, not the map being written.
    EXPECT_EQ(refused.rfind((root / "map" / "sparse").string(), 0), 0u) << refused;
    EXPECT_TRUE(refused.find("images.bin") != std::string::npos || refused.find("points3D.bin") != std::string::npos)
        << refused;
    EXPECT_FALSE(fs::exists(root / "map" / map::kMapFileName));
    // COLMAP's result on this sequence varies from run to run (threads, load): once (the asan
    // run of 2026-12-02 05:52) its model held registered images but not one 3D point. Such a
    // model is refused before there is anything to check: one line naming points3D.bin, no map.
    if (refused.find("the model has no 3D points") != std::string::npos) {
      EXPECT_NE(refused.find("points3D.bin"), std::string::npos) << refused;
      return;
    }
  }
  const auto saved = ReadMapCheck(root / "map" / kMapCheckFileName);
  ASSERT_TRUE(saved) << "check.json is written before the map";
  std::cout << "[still camera] " << DescribeMapCheck(*saved) << "\n";
  ASSERT_TRUE(saved->flagged());
  EXPECT_EQ(saved->warnings, warnings);
  // The still-camera warning, or, when COLMAP's model holds so few of the frames' features that
  // no two keyframes share the points to measure motion with (a CI run of 2026-12-05: 19 of 24
  // registered, 0.6% explained, 0 keyframe pairs), the warning that the scene moved: either
  // tells the user to film a still scene.
  bool still = false;
  for (const auto& w : warnings) {
    still = still || w.find("still camera filming a moving object") != std::string::npos ||
            (saved->moving_pairs == 0 && w.find("the scene changed while it was filmed") != std::string::npos);
  }
  EXPECT_TRUE(still) << (warnings.empty() ? "no warning" : warnings[0]);
}

}  // namespace
}  // namespace arview::mapping
