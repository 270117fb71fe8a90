#pragma once
// The virtual camera of `arview view` (the paper's VR mode, §4.1: "a standard trackball camera
// manipulator"): an orbit around a target point with a fixed up axis, so the horizon never
// rolls. Azimuth and elevation are measured in the character's frame, as key viewpoints are
// (azimuth 0 = the character's forward, +90 toward up × forward, elevation +90 = up), so that
// an orbit at azimuth a looks at the character from the side a key at azimuth a stands on.
// The camera it gives is an ordinary calib::Pose (world → camera, OpenCV axes: x right, y down,
// z forward): the animation is driven by its centre exactly as by a tracked camera's.

#include <Eigen/Core>

#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::app {

struct OrbitState {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // map coordinates
  double azimuth_deg = 0;
  double elevation_deg = 0;  // clamped to ±kMaxElevationDeg
  double distance = 1;       // from the target, map units
};

class OrbitCamera {
 public:
  static constexpr double kMaxElevationDeg = 89;
  // `forward` and `up` are the character's axes in map coordinates (need not be unit; forward
  // is made orthogonal to up).
  OrbitCamera(const Eigen::Vector3d& forward_map, const Eigen::Vector3d& up_map, const OrbitState& start);
  OrbitCamera() : OrbitCamera(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), {}) {}

  const OrbitState& state() const { return state_; }
  void Set(const OrbitState& state);
  void Reset() { Set(home_); }

  // Mouse gestures, in pixels of a window whose camera is `camera`.
  void Orbit(double dx_px, double dy_px);   // drag: right turns the view right (camera moves left)
  void Zoom(double wheel_steps);            // +1: one wheel notch closer (10%)
  void Pan(double dx_px, double dy_px, const calib::Camera& camera);  // the target follows the cursor

  Eigen::Vector3d Center() const;  // camera centre, map coordinates
  calib::Pose Pose() const;        // looking at the target, up axis up in the image

  static constexpr double kDegPerPixel = 0.4;
  static constexpr double kZoomPerStep = 1.1;

 private:
  Eigen::Vector3d forward_, left_, up_;
  OrbitState state_, home_;
};

// A pinhole camera of the given size with a vertical field of view in degrees (square pixels,
// principal point at the image centre).
calib::Camera ViewCamera(int width, int height, double vertical_fov_deg = 45);

}  // namespace arview::app
