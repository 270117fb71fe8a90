#pragma once
// A rigid camera pose in the shared convention: R, t map world to camera
// (x_cam = R·X + t), as COLMAP and OpenCV do; the camera centre is C = −Rᵀt.
// TUM trajectories store the inverse (camera-to-world): position C and rotation Rᵀ.
// Products and inverses go through arview::Rigid3 (base/geometry.h): a Pose is the rigid
// transform world → camera.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "base/geometry.h"

namespace arview::calib {

struct Pose {
  Eigen::Quaterniond q_cw = Eigen::Quaterniond::Identity();  // world → camera rotation
  Eigen::Vector3d t_cw = Eigen::Vector3d::Zero();             // world → camera translation

  Eigen::Matrix3d R() const { return q_cw.toRotationMatrix(); }
  Eigen::Vector3d Center() const { return -(q_cw.conjugate() * t_cw); }
  Eigen::Vector3d ToCamera(const Eigen::Vector3d& world) const { return q_cw * world + t_cw; }
  Eigen::Quaterniond CameraToWorldRotation() const { return q_cw.conjugate(); }

  Rigid3 ToRigid() const { return {q_cw, t_cw}; }
  static Pose FromRigid(const Rigid3& world_to_camera) {
    return {world_to_camera.rotation, world_to_camera.translation};
  }
  // (a * b)(x) = a(b(x)): e.g. a motion applied after a pose, velocity * last.
  Pose operator*(const Pose& b) const { return FromRigid(ToRigid() * b.ToRigid()); }
  Pose Inverse() const { return FromRigid(ToRigid().Inverse()); }

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
