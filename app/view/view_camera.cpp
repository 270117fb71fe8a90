#include "app/view/view_camera.h"

#include <algorithm>
#include <cmath>

namespace arview::app {

namespace {
constexpr double kDeg = M_PI / 180;
}

OrbitCamera::OrbitCamera(const Eigen::Vector3d& forward_map, const Eigen::Vector3d& up_map, const OrbitState& start) {
  up_ = up_map.normalized();
  forward_ = forward_map - forward_map.dot(up_) * up_;
  if (forward_.norm() < 1e-9) forward_ = up_.unitOrthogonal();
  forward_.normalize();
  left_ = up_.cross(forward_);  // azimuth +90°: toward up × forward, as anim's key viewpoints
  Set(start);
  home_ = state_;
}

void OrbitCamera::Set(const OrbitState& s) {
  state_ = s;
  state_.elevation_deg = std::clamp(s.elevation_deg, -kMaxElevationDeg, kMaxElevationDeg);
  state_.azimuth_deg = std::remainder(s.azimuth_deg, 360.0);
  state_.distance = std::max(s.distance, 1e-6);
}

void OrbitCamera::Orbit(double dx_px, double dy_px) {
  OrbitState s = state_;
  // Dragging right carries the scene right under the cursor: the camera goes the other way.
  s.azimuth_deg -= dx_px * kDegPerPixel;
  // Dragging down tips the scene toward the viewer: the camera rises.
  s.elevation_deg += dy_px * kDegPerPixel;
  Set(s);
}

void OrbitCamera::Zoom(double wheel_steps) {
  OrbitState s = state_;
  s.distance /= std::pow(kZoomPerStep, wheel_steps);
  Set(s);
}

void OrbitCamera::Pan(double dx_px, double dy_px, const calib::Camera& camera) {
  const Eigen::Matrix3d R = Pose().R();  // rows: camera x, y, z in map coordinates
  // A pixel at the target's depth spans distance / f map units.
  const double sx = state_.distance / camera.fx, sy = state_.distance / camera.fy;
  OrbitState s = state_;
  s.target -= R.row(0).transpose() * (dx_px * sx) + R.row(1).transpose() * (dy_px * sy);
  Set(s);
}

Eigen::Vector3d OrbitCamera::Center() const {
  const double az = state_.azimuth_deg * kDeg, el = state_.elevation_deg * kDeg;
  const Eigen::Vector3d dir =
      std::cos(el) * (std::cos(az) * forward_ + std::sin(az) * left_) + std::sin(el) * up_;
  return state_.target + state_.distance * dir;
}

calib::Pose OrbitCamera::Pose() const {
  const Eigen::Vector3d c = Center();
  const Eigen::Vector3d z = (state_.target - c).normalized();
  // x = z × up is the image's right for a camera whose y points down (below the horizon).
  const Eigen::Vector3d x = z.cross(up_).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return calib::Pose::FromRt(R, -R * c);
}

calib::Camera ViewCamera(int width, int height, double vertical_fov_deg) {
  const double f = 0.5 * height / std::tan(0.5 * vertical_fov_deg * kDeg);
  return calib::Camera::Pinhole(width, height, f, f, 0.5 * (width - 1), 0.5 * (height - 1));
}

}  // namespace arview::app
