#include "base/point_spread.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Eigenvalues>

namespace arview {

namespace {

std::string Format(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s << std::setprecision(6) << '(' << p.x() << ", " << p.y() << ", " << p.z() << ')';
  return s.str();
}

std::string Format(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

}  // namespace

PointSpread MeasureSpread(const std::vector<Eigen::Vector3d>& points) {
  PointSpread spread;
  if (points.empty()) return spread;
  const double n = static_cast<double>(points.size());
  for (const auto& p : points) spread.mean += p / n;  // each divided first: no overflow of the sum
  double extent = 0;
  for (const auto& p : points) extent = std::max(extent, (p - spread.mean).cwiseAbs().maxCoeff());
  if (!(extent > 0) || !std::isfinite(extent)) return spread;
  // The scatter of the points scaled to unit extent: its squares neither underflow (a map
  // scaled by 1e-300) nor overflow.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    const Eigen::Vector3d d = (p - spread.mean) / extent;
    scatter += d * d.transpose();
  }
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter, Eigen::EigenvaluesOnly).eigenvalues();
  for (int k = 0; k < 3; ++k) spread.sigma[k] = extent * std::sqrt(std::max(ev(2 - k), 0.0) / n);  // descending
  return spread;
}

std::optional<std::string> WhyNotAPlane(const std::vector<Eigen::Vector3d>& points, const std::string& noun) {
  const std::string count = std::to_string(points.size());
  if (points.size() < 3) return "only " + count + " " + noun + " (a plane needs 3)";
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite() || points[i].norm() > kMaxPositionNorm) {
      return "position " + std::to_string(i) + " is " + Format(points[i]) + ", not a finite position within " +
             Format(kMaxPositionNorm) + " of the origin";
    }
  }
  const PointSpread s = MeasureSpread(points);
  // Rounding: 1e-8 of the points' magnitude, far above double rounding (1e-16 relative).
  // Without it, points that are one position up to rounding (every centre (1, 2, 3) read from
  // text) passed, and a fit scored them with a scale of 1e-17.
  const double rounding = 1e-8 * (s.mean.norm() + s.sigma[0]);
  const double least = std::max(rounding, kMinPositionSpread);
  if (!(s.sigma[0] > least)) {
    return "all " + count + " " + noun + " lie at one point, " + Format(s.mean) + ": they spread " + Format(s.sigma[0]) +
           " about it, " +
           (s.sigma[0] <= rounding ? "within the rounding of numbers of that size"
                                   : "below " + Format(kMinPositionSpread) + ", the least spread arview computes with");
  }
  // The second axis against the first: 1e-6 of it (1e-12 of its variance).
  if (!(s.sigma[1] > std::max(1e-6 * s.sigma[0], least))) {
    return "all " + count + " " + noun + " lie on one line: they spread " + Format(s.sigma[0]) + " along it and " +
           Format(s.sigma[1]) + " across it";
  }
  return std::nullopt;
}

}  // namespace arview
