#pragma once
// The resolution the tracker works at. Frames larger than the working size are reduced once
// (grey, cv::INTER_AREA) and every per-frame step (SIFT, flow, matching, RANSAC, the gates) runs
// on the reduced image with the camera model scaled exactly; poses are finally refined against
// the full camera model. One set of pixel constants then holds from 640x480 to 1920x1080.
//
// Scaling in OpenCV's pixel convention (centre of the top-left pixel at 0,0): a full-resolution
// pixel x maps to (x + 0.5)·s − 0.5, so cx' = (cx + 0.5)·sx − 0.5 (not cx·sx, which would shift
// every point by half a pixel of the reduction), fx' = fx·sx; distortion acts on normalised
// coordinates and is unchanged.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/camera.h"

namespace arview::tracker {

// `camera` seen through an image resized to width x height.
calib::Camera ScaleCamera(const calib::Camera& camera, int width, int height);

class WorkingResolution {
 public:
  // long_side: the working image's longest side (0, or at least the camera's: full resolution).
  WorkingResolution(const calib::Camera& full, int long_side);

  const calib::Camera& full() const { return full_; }
  const calib::Camera& work() const { return work_; }
  bool reduced() const { return reduced_; }
  // The working image of a full-resolution 8-bit grey frame (the frame itself when not reduced).
  cv::Mat Reduce(const cv::Mat& full_gray) const;
  // A working pixel in full-resolution pixels.
  Eigen::Vector2d ToFull(const Eigen::Vector2d& work_pixel) const {
    return {(work_pixel.x() + 0.5) / sx_ - 0.5, (work_pixel.y() + 0.5) / sy_ - 0.5};
  }
  // Full-resolution pixels per working pixel (mean of both axes).
  double full_per_work() const { return 0.5 * (1.0 / sx_ + 1.0 / sy_); }

 private:
  calib::Camera full_, work_;
  double sx_ = 1, sy_ = 1;
  bool reduced_ = false;
};

}  // namespace arview::tracker
