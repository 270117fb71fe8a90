#include "anim/placement.h"

namespace arview::anim {

Eigen::Matrix3d Placement::Rotation() const { return anchor.rotation.normalized().toRotationMatrix(); }

Eigen::Matrix4d Placement::ModelToMap() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = Rotation() * ModelScale();
  m.block<3, 1>(0, 3) = anchor.position;
  return m;
}

Eigen::Vector3d Placement::UpInMap() const { return (anchor.rotation.normalized() * up).normalized(); }

Eigen::Vector3d Placement::ViewpointFromCamera(const Eigen::Vector3d& camera_center_map) const {
  const Eigen::Vector3d d = anchor.rotation.normalized().conjugate() * (camera_center_map - anchor.position);
  const double n = d.norm();
  return n > 1e-12 ? Eigen::Vector3d(d / n) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d Placement::MapToModel(const Eigen::Vector3d& point_map) const {
  return Rotation().transpose() * (point_map - anchor.position) / ModelScale();
}

double Placement::FloorDistance(const Eigen::Vector3d& camera_center_map) const {
  // The anchor's rotation as the scene holds it (unit already): the distances are those of the
  // appliance before Placement, to the last digit.
  const Eigen::Vector3d up_map = (anchor.rotation * up).normalized();
  const Eigen::Vector3d to_camera = camera_center_map - anchor.position;
  return (to_camera - to_camera.dot(up_map) * up_map).norm();
}

}  // namespace arview::anim
