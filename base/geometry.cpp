#include "base/geometry.h"

#include <cmath>
#include <sstream>

#include <algorithm>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "base/error.h"

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

namespace {

// The points span at least a plane: the second largest spread is not negligible next to the
// largest (a line or a single point leaves the rotation about it undetermined).
// Whether the points span a plane, relatively (the second principal axis is not negligible
// beside the first) and absolutely: the spread along it, as a standard deviation, exceeds
// 1e-8 of the points' distance from the origin plus their extent, far above double rounding
// (1e-16 relative). Without the absolute test, points that are all one position up to rounding
// (every centre (1, 2, 3) read from text) passed, and the fit scored them with a scale of 1e-17.
bool SpansAPlane(const Eigen::Matrix3Xd& points) {
  const Eigen::Vector3d mean = points.rowwise().mean();
  const Eigen::Matrix3Xd centred = points.colwise() - mean;
  const Eigen::Matrix3d scatter = centred * centred.transpose();
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(ev(2) > 0 && ev(1) > 1e-12 * ev(2))) return false;  // ascending
  const double n = static_cast<double>(points.cols());
  const double second_spread = std::sqrt(ev(1) / n), first_spread = std::sqrt(ev(2) / n);
  return second_spread > 1e-8 * (mean.norm() + first_spread);
}

// Positions this far from the origin overflow the fit's squares (1e308 squared is inf).
constexpr double kMaxPositionNorm = 1e100;

}  // namespace

Sim3 EstimateSim3(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, bool with_scale,
                  const std::string& what) {
  if (src.size() != dst.size()) throw Error(what + ": point lists differ in length");
  const size_t n = src.size();
  if (n < 3) throw Error(what + ": needs at least 3 corresponding positions, has " + std::to_string(n));
  Eigen::Matrix3Xd s(3, n), d(3, n);
  for (size_t i = 0; i < n; ++i) {
    s.col(static_cast<Eigen::Index>(i)) = src[i];
    d.col(static_cast<Eigen::Index>(i)) = dst[i];
  }
  for (size_t i = 0; i < n; ++i) {
    for (const Eigen::Vector3d* p : {&src[i], &dst[i]}) {
      if (!p->allFinite() || p->norm() > kMaxPositionNorm) {
        std::ostringstream msg;
        msg << what << ": position " << i << " is (" << p->x() << ", " << p->y() << ", " << p->z()
            << "), not a finite position within " << kMaxPositionNorm << " of the origin";
        throw Error(msg.str());
      }
    }
  }
  if (!SpansAPlane(s) || !SpansAPlane(d)) {
    throw Error(what + ": the positions are degenerate (all on one line or one point); cannot fit a rotation");
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
