#include "tracker/features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace arview::tracker {
namespace {

// A grey image with one bright Gaussian blob centred at (x0, y0): SIFT's keypoint for it is at
// its centre.
cv::Mat ImageWithBlob(double x0, double y0, double sigma) {
  cv::Mat image(200, 240, CV_8U);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const double r2 = (x - x0) * (x - x0) + (y - y0) * (y - y0);
      image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(60 + 150 * std::exp(-r2 / (2 * sigma * sigma)));
    }
  }
  return image;
}

cv::Point2f NearestKeypoint(const Features& features, cv::Point2f to) {
  cv::Point2f nearest;
  float best = std::numeric_limits<float>::max();
  for (const cv::KeyPoint& k : features.keypoints) {
    const cv::Point2f d = k.pt - to;
    if (d.dot(d) < best) {
      best = d.dot(d);
      nearest = k.pt;
    }
  }
  return nearest;
}

TEST(SiftExtractor, KeypointsLieWhereTheBlobsAreNotAQuarterPixelOff) {
  FeatureOptions options;
  options.contrast_threshold = 0.02;
  const SiftExtractor extractor(options);
  struct Blob {
    double x, y, sigma;
  };
  // Whole, half and quarter pixels, small and larger blobs. Before the offset was taken off,
  // OpenCV put every one 0.22-0.28 px right and down.
  for (const Blob& blob : {Blob{60.0, 120.0, 3.0}, Blob{100.3, 80.7, 2.5}, Blob{170.6, 50.2, 4.0}, Blob{120.25, 140.75, 2.0}}) {
    const Features features = extractor.Extract(ImageWithBlob(blob.x, blob.y, blob.sigma));
    ASSERT_FALSE(features.keypoints.empty());
    const cv::Point2f found = NearestKeypoint(features, cv::Point2f(blob.x, blob.y));
    EXPECT_NEAR(found.x, blob.x, 0.05) << "blob at (" << blob.x << ", " << blob.y << ")";
    EXPECT_NEAR(found.y, blob.y, 0.05) << "blob at (" << blob.x << ", " << blob.y << ")";
  }
}

}  // namespace
}  // namespace arview::tracker
