#include "tracker/features.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/error.h"

namespace arview::tracker {

cv::Mat ToColmapDescriptors(const cv::Mat& sift) {
  if (sift.empty()) return cv::Mat(0, 128, CV_8U);
  if (sift.type() != CV_32F || sift.cols != 128)
    throw Error("ToColmapDescriptors: expected N x 128 CV_32F SIFT descriptors");
  cv::Mat out(sift.rows, 128, CV_8U);
  for (int r = 0; r < sift.rows; ++r) {
    const float* in = sift.ptr<float>(r);
    double l1 = 0;
    for (int c = 0; c < 128; ++c) l1 += std::abs(in[c]);
    std::uint8_t* o = out.ptr<std::uint8_t>(r);
    for (int c = 0; c < 128; ++c) {
      const double v = l1 > 0 ? std::sqrt(std::abs(in[c]) / l1) : 0.0;
      o[c] = static_cast<std::uint8_t>(std::min(255.0, std::round(512.0 * v)));
    }
  }
  return out;
}

cv::Mat ToGray8(const cv::Mat& image) {
  cv::Mat gray = image;
  if (image.channels() == 3) cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4) cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  if (gray.depth() == CV_16U) gray.convertTo(gray, CV_8U, 1.0 / 256.0);
  else if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U);
  return gray;
}

SiftExtractor::SiftExtractor(const FeatureOptions& options)
    : options_(options),
      sift_(cv::SIFT::create(options.max_features, options.octave_layers,
                             options.contrast_threshold, options.edge_threshold, options.sigma)) {}

Features SiftExtractor::Extract(const cv::Mat& image) const {
  Features features;
  features.descriptors = cv::Mat(0, 128, CV_8U);
  // SIFT needs a few octaves of room; smaller frames carry nothing to localise against.
  if (image.empty() || image.cols < 16 || image.rows < 16) return features;
  cv::Mat descriptors;
  sift_->detectAndCompute(ToGray8(image), cv::noArray(), features.keypoints, descriptors);
  // OpenCV's SIFT finds keypoints in the image doubled (first octave -1) by a bilinear resize
  // whose pixel centres are half-pixel aligned, so a point at x of the image lies at 2x + 0.5 of
  // the doubled one; OpenCV halves that, and every keypoint lands a quarter of a pixel right and
  // down of where it is, and of where COLMAP's SIFT puts it in the map (docs/tracker.md, "Sixth
  // round (issue 58): SIFT's quarter pixel").
  for (cv::KeyPoint& keypoint : features.keypoints) keypoint.pt -= cv::Point2f(kOpenCvSiftOffsetPx, kOpenCvSiftOffsetPx);
  features.descriptors = ToColmapDescriptors(descriptors);
  return features;
}

}  // namespace arview::tracker
