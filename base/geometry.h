#pragma once
// Rigid and similarity transforms, as COLMAP's geometry/rigid3.h and sim3.h: one place for
// composing, inverting and applying them, so that no module re-derives a pose product.
//
// Convention: a Rigid3 maps points of a source frame into a target frame,
// x_target = rotation · x_source + translation. A camera pose (calib::Pose) is the rigid
// transform world → camera; its Centre() is the camera centre in the world, C = −Rᵀt.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arview {

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& r, const Eigen::Vector3d& t) : rotation(r), translation(t) {}
  static Rigid3 FromMatrix(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
    return {Eigen::Quaterniond(r).normalized(), t};
  }

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  Eigen::Matrix<double, 3, 4> Matrix3x4() const;
  // The origin of the target frame seen from the source frame: −Rᵀt (a pose's camera centre).
  Eigen::Vector3d Centre() const { return -(rotation.conjugate() * translation); }
  Rigid3 Inverse() const;

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  // (a * b)(x) = a(b(x)); the rotation is renormalised so that long products stay rotations.
  Rigid3 operator*(const Rigid3& b) const;
};

// x ↦ scale · R · x + t: maps positions of one world (a trajectory's, a map's) into another's.
struct Sim3 {
  double scale = 1;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return scale * (R * x) + t; }
  Sim3 Inverse() const;
  Eigen::Matrix4d Matrix() const;
  // The same camera expressed in the target world: a world → camera pose whose centre is mapped
  // and whose orientation is rotated by R (the scale changes positions, not orientations).
  Rigid3 TransformPose(const Rigid3& world_to_camera) const;
};

// The least-squares similarity (with_scale) or rigid motion mapping src[i] onto dst[i]
// (Umeyama 1991, through Eigen::umeyama). Throws arview::Error when the lists differ in length,
// hold fewer than 3 points, or either set is degenerate (all on one line or at one point): a
// rotation is determined only when both span at least a plane. `what` starts the message.
Sim3 EstimateSim3(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, bool with_scale,
                  const std::string& what = "alignment");

// Where something stands in a map: model → map is translate(position) · rotation · scale.
// One type for the scene file's anchor and the placement's result, the rotation stored one way
// (a unit quaternion).
struct Anchor {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // model frame → map frame
  double scale = 1.0;

  Eigen::Matrix4d Matrix() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return position + scale * (rotation * x); }
};

}  // namespace arview
