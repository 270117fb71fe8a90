#pragma once
// A rigid camera pose in the shared convention: R, t map world to camera
// (x_cam = R·X + t), as COLMAP and OpenCV do; the camera centre is C = −Rᵀt.
// TUM trajectories store the inverse (camera-to-world): position C and rotation Rᵀ.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arview::calib {

struct Pose {
  Eigen::Quaterniond q_cw = Eigen::Quaterniond::Identity();  // world → camera rotation
  Eigen::Vector3d t_cw = Eigen::Vector3d::Zero();             // world → camera translation

  Eigen::Matrix3d R() const { return q_cw.toRotationMatrix(); }
  Eigen::Vector3d Center() const { return -(q_cw.conjugate() * t_cw); }
  Eigen::Vector3d ToCamera(const Eigen::Vector3d& world) const { return q_cw * world + t_cw; }
  Eigen::Quaterniond CameraToWorldRotation() const { return q_cw.conjugate(); }

  static Pose FromRt(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
    return {Eigen::Quaterniond(R).normalized(), t};
  }
  // From camera-to-world rotation and camera centre (TUM, OpenGV).
  static Pose FromCameraToWorld(const Eigen::Quaterniond& q_wc, const Eigen::Vector3d& center) {
    const Eigen::Quaterniond q = q_wc.conjugate().normalized();
    return {q, -(q * center)};
  }
};

}  // namespace arview::calib
