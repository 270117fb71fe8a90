#pragma once
// SIFT features of a frame with descriptors in COLMAP's uint8 convention, so that they can be
// matched against the map's descriptors (map/map.h).

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <vector>

#include "base/option_check.h"

namespace arview::tracker {

struct FeatureOptions {
  int max_features = 1000;  // strongest responses kept (0 = all)
  int octave_layers = 3;
  // OpenCV keeps an extremum when |DoG| >= contrast_threshold / octave_layers; COLMAP (the map's
  // features) when |DoG| >= peak_threshold, 0.02 / 3 by default: 0.02 is the same test as
  // COLMAP's, 0.04 (OpenCV's default) keeps only the stronger half of the structure.
  double contrast_threshold = 0.04;
  double edge_threshold = 10;
  double sigma = 1.6;

  // Throws OptionError naming the first bad field (base/option_check.h; tracker/tracker_options.cpp).
  void Check(const OptionNames& names = {}) const;
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;  // OpenCV pixel convention
  cv::Mat descriptors;                  // keypoints.size() x 128, CV_8U, COLMAP convention
};

// Float SIFT descriptors (N x 128, CV_32F) to COLMAP's: L1-normalise each row, square root,
// x512, round, clamp to 255, uint8.
cv::Mat ToColmapDescriptors(const cv::Mat& sift);

// Where OpenCV's SIFT (4.6, and later ones without `enable_precise_upscale`) puts a keypoint,
// right of and below where it is, in pixels of the image given to it; Extract() takes it off.
inline constexpr float kOpenCvSiftOffsetPx = 0.25f;

// Reuses one cv::SIFT detector across frames.
class SiftExtractor {
 public:
  explicit SiftExtractor(const FeatureOptions& options = {});
  // image: 8-bit grey or BGR. An empty or tiny image gives no features (never throws).
  // Keypoints where they are in `image` (OpenCV's quarter-pixel offset taken off).
  Features Extract(const cv::Mat& image) const;
  const FeatureOptions& options() const { return options_; }

 private:
  FeatureOptions options_;
  cv::Ptr<cv::SIFT> sift_;
};

// 8-bit single-channel view of a frame (converted when it is BGR, BGRA or 16-bit).
cv::Mat ToGray8(const cv::Mat& image);

}  // namespace arview::tracker
