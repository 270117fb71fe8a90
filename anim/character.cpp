#include "anim/character.h"

namespace arview::anim {

Eigen::Matrix4d Transform::ToMatrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = rotation.normalized().toRotationMatrix() * scale.asDiagonal();
  m.block<3, 1>(0, 3) = translation;
  return m;
}

Transform Transform::FromMatrix(const Eigen::Matrix4d& m) {
  Transform t;
  t.translation = m.block<3, 1>(0, 3);
  Eigen::Matrix3d a = m.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) t.scale[c] = a.col(c).norm();
  if (a.determinant() < 0) t.scale.z() = -t.scale.z();
  Eigen::Matrix3d r;
  for (int c = 0; c < 3; ++c) r.col(c) = t.scale[c] != 0 ? Eigen::Vector3d(a.col(c) / t.scale[c]) : Eigen::Vector3d::Unit(c);
  // Re-orthonormalise: files carry rounding in their matrices.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  r = svd.matrixU() * svd.matrixV().transpose();
  t.rotation = Eigen::Quaterniond(r).normalized();
  return t;
}

int Skeleton::Find(const std::string& name) const {
  for (int j = 0; j < size(); ++j)
    if (names[j] == name) return j;
  return -1;
}

int Skeleton::FindMorphTarget(const std::string& name) const {
  for (int k = 0; k < morph_target_count(); ++k)
    if (morph_targets[k] == name) return k;
  return -1;
}

const Clip* Character::FindClip(const std::string& name) const {
  for (const Clip& c : clips)
    if (c.name == name) return &c;
  return nullptr;
}

}  // namespace arview::anim
