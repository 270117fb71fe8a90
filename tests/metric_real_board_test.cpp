// A real board, mapped: OpenCV's stereo sample (Debian package opencv-doc: a fixed stereo rig
// photographs a 9x6 chessboard of 25 mm squares, as its left_intrinsics.yml says, held at 13
// places). Each camera is calibrated from its own 13 photos, every photo undistorted to one
// shared pinhole camera, and the 26 mapped with COLMAP (`arview map`'s pipeline). Each place's
// board is then found in its two photos, triangulated from the two keyframes' poses, and fitted
// to the 9x6 grid (mapping/metric_frame.h): its scale, map units → metres. Made metric from the
// other places' boards, each place's board must come out at its true square size. The figures
// are in docs/mapping.md, "Metric scale and up".

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// A measurement, run on request (ARVIEW_REAL_BOARD=1): COLMAP's map of this scene fails
// wholesale in about one run in three (below), so that even three tries leave the suite at the
// mercy of COLMAP's threads.
TEST(MetricRealBoard, EveryPlaceOfOpenCvsStereoSampleBoardHasItsTrueSquareSize) {
  if (const char* on = std::getenv("ARVIEW_REAL_BOARD"); !on || std::string(on) != "1")
    GTEST_SKIP() << "set ARVIEW_REAL_BOARD=1 to map OpenCV's stereo sample with COLMAP (2-3 min; docs/mapping.md)";
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

  // map units → metres, one per place whose two photos agree, from one COLMAP map.
  struct Measured {
    std::vector<double> scales;
    int refused = 0;
  };
  const auto measure = [&](const fs::path& map_dir) {
    mapping::MapBuildOptions options;
    options.matcher = mapping::MatcherKind::kExhaustive;
    options.max_num_features = 4096;  // half COLMAP's default: the 26 photos match in half the time
    const mapping::MapBuildResult built = mapping::BuildMap(recording, map_dir, options);
    const map::Map& map = built.map;
    Measured m;
    if (map.keyframes.size() < 20u) return m;
    const std::vector<mapping::BoardSighting> seen = mapping::FindBoard(
        map,
        [&](std::size_t k) { return cv::imread((recording.root / map.keyframes[k].name).string(), cv::IMREAD_GRAYSCALE); },
        {9, 6});
    std::map<int, std::vector<mapping::BoardSighting>> by_place;
    for (const mapping::BoardSighting& s : seen) by_place[map.keyframes[s.keyframe].frame_index % places].push_back(s);
    for (const auto& [place, sightings] : by_place) {
      if (sightings.size() != 2) continue;
      try {
        const mapping::TriangulatedBoard board = mapping::TriangulateBoard(map, sightings, {9, 6});
        const mapping::MetricFit fit = mapping::FitFromBoard(map, board, {{9, 6}, kSquare, false});
        std::printf("place %2d: corners %.3f px, views %.1f deg apart, fit %.2f mm, scale %.5f\n", place + 1,
                    board.rms_reprojection_px, board.widest_angle_deg, 1000 * fit.fit_rms_m, fit.to_metric.scale);
        EXPECT_LT(fit.fit_rms_m, 0.1 * kSquare);  // the corners form the grid
        m.scales.push_back(fit.to_metric.scale);
      } catch (const map::MapError& e) {
        // Two keyframes whose poses do not agree on the board: refused, as `map scale` would.
        std::printf("place %2d: refused: %s\n", place + 1, e.what());
        ++m.refused;
      }
    }
    return m;
  };
  // COLMAP's result differs from run to run (its threads), and this scene is hard for it: two
  // camera poses only, the board moving between the photos. One run in four posed the two
  // cameras so that no board could be triangulated (every place refused, as it should be): the
  // map is built again then, up to three times, as one would with any stochastic step.
  Measured measured;
  for (int attempt = 1; attempt <= 3 && measured.scales.size() < 8u; ++attempt) {
    if (attempt > 1) std::printf("COLMAP's map %d let too few boards be fitted: mapping again\n", attempt - 1);
    measured = measure(root / ("map-" + std::to_string(attempt)));
  }
  const std::vector<double>& scales = measured.scales;
  const int refused = measured.refused;
  ASSERT_GE(scales.size(), 8u) << refused << " places refused";
  // Each place's squares measured through the others' scale (their median): as if the map had
  // been made metric from another board.
  std::vector<double> errors;
  for (std::size_t i = 0; i < scales.size(); ++i) {
    std::vector<double> others = scales;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
    errors.push_back(std::abs(Median(others) / scales[i] - 1));
  }
  const double worst = *std::max_element(errors.begin(), errors.end());
  const auto within = std::count_if(errors.begin(), errors.end(), [](double e) { return e <= 0.05; });
  std::printf("%zu places fitted, %d refused; square size through the other places' scale: median error %.2f%% "
              "(%.2f mm of 25), %td within 5%%, worst %.2f%%\n",
              scales.size(), refused, 100 * Median(errors), 25 * Median(errors), within, 100 * worst);
  // A place seen in two photos only has no third view to outvote a bad pair: one run had a place
  // 45% off (docs/mapping.md).
  EXPECT_LT(Median(errors), 0.02);
  EXPECT_GE(4 * within, 3 * static_cast<std::ptrdiff_t>(errors.size()));
  if (!keep) fs::remove_all(root);
}

}  // namespace
}  // namespace arview
