#pragma once
// A photo-like test image (smooth shading, shapes, a little noise): encoders make Huffman codes
// of every length and filters of every kind for it, as for a real frame.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace arview::testing {

inline cv::Mat PhotoLikePicture(int width, int height) {
  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) image.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 255 / width, y * 255 / height, 128);
  }
  cv::RNG rng(7);
  for (int i = 0; i < 12; ++i) {
    cv::circle(image, {rng.uniform(0, width), rng.uniform(0, height)}, rng.uniform(2, 12),
               cv::Scalar(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256)), -1);
  }
  cv::Mat noise(height, width, CV_8UC3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 24);
  return image + noise;
}

}  // namespace arview::testing
