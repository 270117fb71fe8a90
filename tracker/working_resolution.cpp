#include "tracker/working_resolution.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace arview::tracker {

calib::Camera ScaleCamera(const calib::Camera& camera, int width, int height) {
  const double sx = static_cast<double>(width) / camera.width;
  const double sy = static_cast<double>(height) / camera.height;
  calib::Camera scaled = camera;
  scaled.width = width;
  scaled.height = height;
  scaled.fx = camera.fx * sx;
  scaled.fy = camera.fy * sy;
  scaled.cx = (camera.cx + 0.5) * sx - 0.5;
  scaled.cy = (camera.cy + 0.5) * sy - 0.5;
  return scaled;
}

WorkingResolution::WorkingResolution(const calib::Camera& full, int long_side) : full_(full), work_(full) {
  const int longest = std::max(full.width, full.height);
  if (long_side <= 0 || long_side >= longest) return;
  const double s = static_cast<double>(long_side) / longest;
  const int width = std::max(1, static_cast<int>(std::lround(full.width * s)));
  const int height = std::max(1, static_cast<int>(std::lround(full.height * s)));
  // Each axis keeps its own exact factor (the rounded size over the full size).
  sx_ = static_cast<double>(width) / full.width;
  sy_ = static_cast<double>(height) / full.height;
  work_ = ScaleCamera(full, width, height);
  reduced_ = true;
}

cv::Mat WorkingResolution::Reduce(const cv::Mat& full_gray) const {
  if (!reduced_) return full_gray;
  cv::Mat work;
  cv::resize(full_gray, work, work_.Size(), 0, 0, cv::INTER_AREA);
  return work;
}

}  // namespace arview::tracker
