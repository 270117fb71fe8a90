#include "base/geometry.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "base/error.h"
#include "base/point_spread.h"

namespace arview {

Eigen::Matrix<double, 3, 4> Rigid3::Matrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation;
  return m;
}

Rigid3 Rigid3::Inverse() const {
  const Eigen::Quaterniond inv = rotation.conjugate();
  return {inv, -(inv * translation)};
}

Rigid3 Rigid3::operator*(const Rigid3& b) const {
  return {(rotation * b.rotation).normalized(), rotation * b.translation + translation};
}

Sim3 Sim3::Inverse() const {
  Sim3 inv;
  inv.scale = 1.0 / scale;
  inv.R = R.transpose();
  inv.t = -(inv.scale * (inv.R * t));
  return inv;
}

Eigen::Matrix4d Sim3::Matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = scale * R;
  m.topRightCorner<3, 1>() = t;
  return m;
}

Rigid3 Sim3::TransformPose(const Rigid3& world_to_camera) const {
  const Eigen::Quaterniond q_wc(R * world_to_camera.rotation.conjugate().toRotationMatrix());
  const Eigen::Quaterniond q_cw = q_wc.conjugate().normalized();
  return {q_cw, -(q_cw * (*this)(world_to_camera.Centre()))};
}

Sim3 EstimateSim3(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, bool with_scale,
                  const std::string& what) {
  if (src.size() != dst.size()) throw Error(what + ": point lists differ in length");
  const size_t n = src.size();
  if (n < 3) throw Error(what + ": needs at least 3 corresponding positions, has " + std::to_string(n));
  for (const auto* points : {&src, &dst}) {
    if (const auto why = WhyNotAPlane(*points, "positions")) {
      throw Error(what + ": " + (why->rfind("position ", 0) == 0 ? *why : "the positions are degenerate: " + *why) +
                  "; cannot fit a rotation");
    }
  }
  Eigen::Matrix3Xd s(3, n), d(3, n);
  for (size_t i = 0; i < n; ++i) {
    s.col(static_cast<Eigen::Index>(i)) = src[i];
    d.col(static_cast<Eigen::Index>(i)) = dst[i];
  }
  const Eigen::Matrix4d m = Eigen::umeyama(s, d, with_scale);
  Sim3 out;
  out.scale = with_scale ? m.topLeftCorner<3, 3>().col(0).norm() : 1.0;
  out.R = m.topLeftCorner<3, 3>() / out.scale;
  out.t = m.topRightCorner<3, 1>();
  return out;
}

Eigen::Matrix4d Anchor::Matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = scale * rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = position;
  return m;
}

}  // namespace arview
