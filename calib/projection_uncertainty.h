#pragma once
// How well a calibration knows where a point projects, over the whole image, as mrcal measures
// it (docs/calibration.md): the fit's covariance (the observed corners' noise, estimated from the
// residuals, propagated through the least-squares solution of intrinsics and board poses) carried
// to the projection of a point at a working distance. As mrcal's "mean-frames" method, the point
// is held fixed relative to the boards (the mean of where each board's frame puts it), not to
// the camera: an error in the principal point that the boards' poses absorb moves nothing seen
// in the region the boards covered, and so is not counted there. A low RMS from views that all
// sit in the middle is a poor calibration: its uncertainty is low in the middle and high at the
// edges, and this says so where RMS cannot.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/option_check.h"
#include "calib/calibration.h"

namespace arview::calib {

struct UncertaintyOptions {
  double distance_m = 1.0;  // the working distance (depth along the optical axis), metres
  int grid_columns = 32;    // image points evaluated across; rows in proportion
  // A region whose median uncertainty exceeds this is named in the warning (pixels, 1-sigma in
  // the worst direction): a point there may project a pixel or more from where the camera sees
  // it, which the tracker's pose then absorbs as error.
  double poor_px = 1.0;

  void Check(const OptionNames& names = {}) const;
};

struct ProjectionUncertainty {
  UncertaintyOptions options;
  double corner_noise_px = 0;  // the residuals' standard deviation per coordinate (mrcal's)
  cv::Mat grid;                // CV_64F, rows x grid_columns: 1-sigma worst-direction stdev, pixels
  cv::Size image_size;
  double centre_px = 0, median_px = 0, worst_px = 0;
  // The nine regions (3 x 3) and their median uncertainty, from "top left" to "bottom right".
  std::vector<std::pair<std::string, double>> regions;
  // The regions beyond options.poor_px, worst first; empty when none.
  std::vector<std::string> poor_regions;

  // The image point of grid cell (row, column), pixels.
  cv::Point2d GridPoint(int row, int column) const;
  // "projection uncertainty at 1 m: 0.08 px at the centre, median 0.11, worst 0.62 (bottom right)".
  std::string Summary() const;
  // One line naming the uncovered regions and what to do; empty when none is poor.
  std::string Warning() const;
};

// `result` must hold the final pass's views and board poses (Calibrate, CalibrateDetections).
// Throws CalibrationError when the fit has no degrees of freedom left (too few corners).
ProjectionUncertainty EstimateProjectionUncertainty(const CalibrationResult& result, const UncertaintyOptions& options = {});

// A picture of the uncertainty over the image: a colour map (blue low, red at 2 x poor_px and
// above), the line where it crosses poor_px, the corners used as dots, and the figures written
// on it; the image's size.
cv::Mat DrawProjectionUncertainty(const ProjectionUncertainty& uncertainty,
                                  const std::vector<std::vector<cv::Point2f>>& corners);

}  // namespace arview::calib
