#include "base/plane_fit.h"

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "base/error.h"
#include "base/point_spread.h"
#include "base/stats.h"

namespace arview {

Eigen::Vector3d ComponentMedian(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d m;
  std::vector<double> v(points.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < points.size(); ++i) v[i] = points[i][axis];
    m[axis] = Median(v);
  }
  return m;
}

double MedianDistance(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& from) {
  std::vector<double> d;
  d.reserve(points.size());
  for (const auto& p : points) d.push_back((p - from).norm());
  return Median(d);
}

namespace {

// Least-squares plane through the inliers of a RANSAC hypothesis.
Plane RefitPlane(const std::vector<Eigen::Vector3d>& points, const Plane& guess, double threshold) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<const Eigen::Vector3d*> in;
  for (const auto& p : points) {
    if (std::abs(guess.Distance(p)) < threshold) in.push_back(&p);
  }
  if (in.size() < 3) return guess;
  for (const auto* p : in) mean += *p;
  mean /= static_cast<double>(in.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto* p : in) cov += (*p - mean) * (*p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Plane plane;
  plane.normal = eig.eigenvectors().col(0).normalized();
  plane.offset = -plane.normal.dot(mean);
  plane.inliers = 0;
  for (const auto& p : points) plane.inliers += std::abs(plane.Distance(p)) < threshold;
  return plane;
}

}  // namespace

Plane FitDominantPlane(const std::vector<Eigen::Vector3d>& all_points, const PlaneFitOptions& o) {
  if (all_points.size() < 3) throw Error("the map has fewer than 3 points: no plane to stand on");
  if (const auto why = WhyNotAPlane(all_points, "points")) throw Error("no plane to stand on: " + *why);
  const Eigen::Vector3d middle = ComponentMedian(all_points);
  const double extent = 2 * MedianDistance(all_points, middle);
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : all_points) {
    if ((p - middle).norm() <= o.middle_fraction * extent) points.push_back(p);
  }
  if (points.size() < 3) points = all_points;
  const double threshold = o.inlier_distance > 0 ? o.inlier_distance : 0.01 * extent;

  const double cos_max_tilt = std::cos(o.max_tilt_deg * M_PI / 180);
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  Plane best;
  best.inliers = -1;
  for (int it = 0; it < o.iterations; ++it) {
    const Eigen::Vector3d& a = points[pick(rng)];
    const Eigen::Vector3d& b = points[pick(rng)];
    const Eigen::Vector3d& c = points[pick(rng)];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 1e-12 * extent * extent)) continue;  // collinear, at any scale of map
    Plane h;
    h.normal = n.normalized();
    if (o.up_prior && std::abs(h.normal.dot(*o.up_prior)) < cos_max_tilt) continue;
    h.offset = -h.normal.dot(a);
    for (const auto& p : points) h.inliers += std::abs(h.Distance(p)) < threshold;
    if (h.inliers > best.inliers) best = h;
  }
  if (best.inliers < 3) {
    throw Error(o.up_prior ? "no floor-like plane (within the tilt limit of up) holds 3 or more of the map's points"
                           : "no plane holds 3 or more of the map's points (the points are degenerate)");
  }
  return RefitPlane(points, best, threshold);
}

Eigen::Vector3d UpFromCameras(const std::vector<Eigen::Vector3d>& centres, const std::vector<Eigen::Vector3d>& up_axes) {
  Eigen::Vector3d mean_up = Eigen::Vector3d::Zero();
  for (const auto& u : up_axes) mean_up += u.normalized();
  Eigen::Vector3d up = mean_up;
  if (centres.size() >= 3) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& c : centres) mean += c;
    mean /= centres.size();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& c : centres) cov += (c - mean) * (c - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    // A plane of centres: the two larger spreads are comparable, the third much smaller.
    if (eig.eigenvalues()(1) > 0.05 * eig.eigenvalues()(2) && eig.eigenvalues()(0) < 0.3 * eig.eigenvalues()(1)) {
      up = eig.eigenvectors().col(0);
      if (up.dot(mean_up) < 0) up = -up;
    }
  }
  if (up.norm() < 1e-9) throw Error("cannot tell which way is up from the map's cameras");
  return up.normalized();
}

Plane FitFloorUnderCameras(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& camera_centres,
                           const std::vector<Eigen::Vector3d>& camera_up_axes, PlaneFitOptions options,
                           Eigen::Vector3d* up) {
  if (!options.up_prior) options.up_prior = UpFromCameras(camera_centres, camera_up_axes);
  Plane floor = FitDominantPlane(points, options);
  double side = 0;
  for (const auto& c : camera_centres) side += floor.Distance(c);
  if (side < 0) {
    floor.normal = -floor.normal;
    floor.offset = -floor.offset;
  }
  if (up) *up = *options.up_prior;
  return floor;
}

}  // namespace arview
