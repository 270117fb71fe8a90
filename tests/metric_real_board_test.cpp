// A real board, mapped: OpenCV's stereo sample (Debian package opencv-doc: a fixed stereo rig
// photographs a 9x6 chessboard of 25 mm squares, as its left_intrinsics.yml says, held at 13
// places). Each camera is calibrated from its own 13 photos, every photo undistorted to one
// shared pinhole camera, and the 26 mapped with COLMAP (`arview map`'s pipeline). Each place's
// board is then found in its two photos, triangulated from the two keyframes' poses, and fitted
// to the 9x6 grid (mapping/metric_frame.h): its scale, map units → metres. Made metric from one
// place's board, every other place's board must come out at its true square size. The figures
// are in docs/mapping.md, "Metric scale and up".

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "base/stats.h"
#include "calib/calibration.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/metric_frame.h"
#include "recordings/recording.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSample = "/usr/share/doc/opencv-doc/examples/data";
constexpr double kSquare = 0.025;  // metres (the sample's left_intrinsics.yml)

std::vector<std::string> Photos(const std::string& side) {
  std::vector<std::string> photos;
  for (int i = 1; i <= 14; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/%s%02d.jpg", side.c_str(), i);
    if (fs::exists(std::string(kSample) + name)) photos.push_back(std::string(kSample) + name);
  }
  return photos;
}

// The 26 photos undistorted to one pinhole camera: frames 0-12 left, 13-25 right, place by place.
recordings::Recording WriteRecording(const fs::path& root) {
  const calib::Camera shared = calib::Camera::Pinhole(640, 480, 535, 535, 319.5, 239.5);
  fs::create_directories(root / "frames");
  std::vector<recordings::FrameEntry> frames;
  for (const std::string side : {"left", "right"}) {
    const std::vector<std::string> photos = Photos(side);
    calib::CalibrationOptions options;
    options.square_size = kSquare;
    const calib::Camera own = calib::Calibrate(photos, options).camera;
    for (const std::string& photo : photos) {
      cv::Mat undistorted;
      cv::undistort(cv::imread(photo), undistorted, own.K(), own.DistCoeffs(), shared.K());
      char name[32];
      std::snprintf(name, sizeof name, "frames/%06zu.png", frames.size());
      cv::imwrite((root / name).string(), undistorted);
      frames.push_back({static_cast<double>(frames.size()), name});
    }
  }
  calib::SaveCamera(shared, root / "camera.yaml");
  recordings::WriteFramesTxt(root, frames);
  return recordings::LoadRecording(root);
}

TEST(MetricRealBoard, EveryPlaceOfOpenCvsStereoSampleBoardHasItsTrueSquareSize) {
  ARVIEW_REQUIRE_DATA_PATH(std::string(kSample) + "/left01.jpg", "Debian package opencv-doc");
  // ARVIEW_METRIC_REAL_BOARD_DIR keeps the recording and the map there (a re-run re-uses them).
  const char* keep = std::getenv("ARVIEW_METRIC_REAL_BOARD_DIR");
  const fs::path root = keep && *keep ? fs::path(keep)
                                      : fs::temp_directory_path() / ("arview_metric_real_board_" + std::to_string(::getpid()));
  if (!keep) fs::remove_all(root);
  const recordings::Recording recording =
      fs::exists(root / "rec" / "frames.txt") ? recordings::LoadRecording(root / "rec") : WriteRecording(root / "rec");
  const int places = static_cast<int>(recording.frames.size()) / 2;
  ASSERT_EQ(places, 13);

  mapping::MapBuildOptions options;
  options.matcher = mapping::MatcherKind::kExhaustive;
  const mapping::MapBuildResult built = mapping::BuildMap(recording, root / "map", options);
  const map::Map& map = built.map;
  ASSERT_GE(map.keyframes.size(), 20u) << "COLMAP registered too few of the 26 photos";

  const std::vector<mapping::BoardSighting> seen = mapping::FindBoard(
      map, [&](std::size_t k) { return cv::imread((recording.root / map.keyframes[k].name).string(), cv::IMREAD_GRAYSCALE); },
      {9, 6});
  std::map<int, std::vector<mapping::BoardSighting>> by_place;
  for (const mapping::BoardSighting& s : seen) by_place[map.keyframes[s.keyframe].frame_index % places].push_back(s);

  std::vector<double> scales;  // map units → metres, one per place seen in both photos
  std::vector<int> place_of;
  for (const auto& [place, sightings] : by_place) {
    if (sightings.size() != 2) continue;
    const mapping::TriangulatedBoard board = mapping::TriangulateBoard(map, sightings, {9, 6});
    const mapping::MetricFit fit = mapping::FitFromBoard(map, board, {{9, 6}, kSquare, false});
    std::printf("place %2d: corners %.3f px, views %.1f deg apart, fit %.2f mm, scale %.5f\n", place + 1,
                board.rms_reprojection_px, board.widest_angle_deg, 1000 * fit.fit_rms_m, fit.to_metric.scale);
    EXPECT_LT(fit.fit_rms_m, 0.1 * kSquare);  // the corners form the grid
    scales.push_back(fit.to_metric.scale);
    place_of.push_back(place);
  }
  ASSERT_GE(scales.size(), 8u);
  // Made metric from each place in turn, the others' squares: worst error over all the pairs.
  double worst = 0;
  std::vector<double> errors;
  for (std::size_t from = 0; from < scales.size(); ++from) {
    for (std::size_t other = 0; other < scales.size(); ++other) {
      if (other == from) continue;
      const double square = kSquare * scales[from] / scales[other];
      errors.push_back(std::abs(square / kSquare - 1));
      worst = std::max(worst, errors.back());
    }
  }
  std::printf("%zu places; squares measured through another place's scale: median error %.2f%%, worst %.2f%%\n",
              scales.size(), 100 * Median(errors), 100 * worst);
  EXPECT_LT(Median(errors), 0.01);
  EXPECT_LT(worst, 0.03);
  if (!keep) fs::remove_all(root);
}

}  // namespace
}  // namespace arview
