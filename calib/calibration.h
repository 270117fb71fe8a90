#pragma once
// Camera calibration from photos of a chessboard (inner corners) or a ChArUco board:
// detection with sub-pixel refinement, cv::calibrateCamera, per-view errors, automatic
// rejection of outlier views followed by a second pass, and coverage of the image.

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/camera.h"

namespace arview::calib {

struct CalibrationError : Error {
  using Error::Error;
};

enum class BoardKind { kChessboard, kCharuco };

struct CalibrationOptions {
  BoardKind kind = BoardKind::kChessboard;
  // Chessboard: inner corners per row and column. ChArUco: squares per row and column.
  cv::Size board{9, 6};
  double square_size = 0.025;      // metres
  double marker_size = 0.0;        // ChArUco marker side, metres (0: 0.7 × square_size)
  std::string charuco_dictionary = "DICT_5X5_100";
  // A view is rejected when its RMS exceeds max(reject_factor × median view RMS, reject_floor_px).
  double reject_factor = 3.0;
  double reject_floor_px = 1.0;
  int min_views = 3;
  int coverage_grid = 16;          // the image is split into coverage_grid × (3/4 of it) cells
};

struct ViewReport {
  std::string path;
  bool board_found = false;
  int corners = 0;
  double rms = 0;       // pixels, after the final pass (or the first, for rejected views)
  bool rejected = false;
};

struct CalibrationResult {
  Camera camera;
  double rms = 0;  // over the views used, pixels
  std::vector<ViewReport> views;
  int views_used = 0;
  int views_rejected = 0;
  int views_without_board = 0;
  double coverage = 0;  // fraction of coverage cells holding at least one used corner
  std::vector<std::vector<cv::Point2f>> used_corners;  // for the report picture
};

// Expands a shell glob to the sorted list of matching files; throws CalibrationError when
// nothing matches.
std::vector<std::string> ExpandImageGlob(const std::string& pattern);

// `progress(i, n)` is called as each image is examined.
CalibrationResult Calibrate(const std::vector<std::string>& image_paths, const CalibrationOptions& options,
                            const std::function<void(int, int)>& progress = {});

// A picture of the corner coverage (left) and the per-view errors (right).
cv::Mat DrawCalibrationReport(const CalibrationResult& result);

// The inner corners of a chessboard (`inner_corners`: per row, per column) in a grey image, row
// after row, refined to sub-pixel as calibration refines them; empty when the board is not found
// whole.
std::vector<cv::Point2f> FindChessboardCorners(const cv::Mat& gray, cv::Size inner_corners);

// Renders a ChArUco board image for printing or for tests.
cv::Mat DrawCharucoBoard(const CalibrationOptions& options, int pixels_per_square);

}  // namespace arview::calib
