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

// A board found in one image: its corners' pixels and the same corners on the board (metres,
// z = 0), in the same order.
struct BoardDetection {
  std::vector<cv::Point2f> image_points;
  std::vector<cv::Point3f> object_points;
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
  // The views of the final pass and each board's pose in the camera (rvec, tvec as
  // cv::calibrateCamera gives them), for the projection uncertainty (calib/projection_uncertainty.h).
  std::vector<BoardDetection> used_views;
  std::vector<cv::Vec3d> rvecs, tvecs;
};

// Expands a shell glob to the sorted list of matching files; throws CalibrationError when
// nothing matches.
std::vector<std::string> ExpandImageGlob(const std::string& pattern);

// `progress(i, n)` is called as each image is examined.
CalibrationResult Calibrate(const std::vector<std::string>& image_paths, const CalibrationOptions& options,
                            const std::function<void(int, int)>& progress = {});

// Calibration from boards already found (`labels[i]` names view i in the report: a file, a
// frame); `images_without_board` of the images looked at held none. Rejects outlier views and
// calibrates again without them, as Calibrate does.
CalibrationResult CalibrateDetections(const std::vector<BoardDetection>& views, const std::vector<std::string>& labels,
                                      cv::Size image_size, const CalibrationOptions& options,
                                      int images_without_board = 0);

// The board of `options` in a grey image; false when it is not found whole (a chessboard) or
// with fewer than 6 corners (ChArUco).
bool DetectBoard(const cv::Mat& gray, const CalibrationOptions& options, BoardDetection* detection);

// The board's corners on the board (metres, z = 0), row after row: what a chessboard's
// detection pairs with its image corners.
std::vector<cv::Point3f> ChessboardObjectPoints(const CalibrationOptions& options);

// A picture of the corner coverage (left) and the per-view errors (right).
cv::Mat DrawCalibrationReport(const CalibrationResult& result);

// The inner corners of a chessboard (`inner_corners`: per row, per column) in a grey image, row
// after row, refined to sub-pixel as calibration refines them; empty when the board is not found
// whole.
std::vector<cv::Point2f> FindChessboardCorners(const cv::Mat& gray, cv::Size inner_corners);

// The same for frames of a live camera, many without a board: the classic detector alone, with
// its quick check that a board is there first and without its adaptive threshold, without the
// exhaustive sector-based fallback meant for still photos, and with the same sub-pixel
// refinement.
std::vector<cv::Point2f> FindChessboardCornersQuickly(const cv::Mat& gray, cv::Size inner_corners);

// Renders a ChArUco board image for printing or for tests: `margin_px` of white all round (-1:
// half a square, the squares then a little smaller than `pixels_per_square`; 0 or more: every
// square exactly `pixels_per_square`, the image the squares plus twice the margin).
cv::Mat DrawCharucoBoard(const CalibrationOptions& options, int pixels_per_square, int margin_px = -1);

}  // namespace arview::calib
