#include "room/scene_proxy.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

namespace arview::room {
namespace {

struct PlaneFit {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;
};

double RobustExtent(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d lo, hi;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> v;
    v.reserve(points.size());
    for (const auto& p : points) v.push_back(p[a]);
    const size_t i5 = v.size() / 20, i95 = v.size() - 1 - v.size() / 20;
    std::nth_element(v.begin(), v.begin() + i5, v.end());
    lo[a] = v[i5];
    std::nth_element(v.begin(), v.begin() + i95, v.end());
    hi[a] = v[i95];
  }
  return std::max((hi - lo).norm(), 1e-9);
}

// Least squares through the points (smallest principal axis).
PlaneFit FitPlane(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& subset) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : subset) mean += points[i];
  mean /= static_cast<double>(subset.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i : subset) scatter += (points[i] - mean) * (points[i] - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  PlaneFit fit;
  fit.normal = solver.eigenvectors().col(0).normalized();
  fit.offset = -fit.normal.dot(mean);
  return fit;
}

std::vector<int> Inliers(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& remaining,
                         const PlaneFit& plane, double distance) {
  std::vector<int> inliers;
  for (int i : remaining) {
    if (std::abs(plane.normal.dot(points[i]) + plane.offset) <= distance) inliers.push_back(i);
  }
  return inliers;
}

std::vector<int> RansacPlane(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& remaining,
                             double distance, int iterations, std::mt19937_64& rng) {
  std::vector<int> best;
  if (remaining.size() < 3) return best;
  const auto pick = [&] { return remaining[rng() % remaining.size()]; };
  for (int it = 0; it < iterations; ++it) {
    const Eigen::Vector3d& a = points[pick()];
    const Eigen::Vector3d& b = points[pick()];
    const Eigen::Vector3d& c = points[pick()];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-12) continue;
    PlaneFit plane{n.normalized(), 0};
    plane.offset = -plane.normal.dot(a);
    // Cheap count first; keep the inlier list only for a better plane.
    int count = 0;
    for (int i : remaining) count += std::abs(plane.normal.dot(points[i]) + plane.offset) <= distance;
    if (count > static_cast<int>(best.size())) best = Inliers(points, remaining, plane, distance);
  }
  if (best.size() < 3) return best;
  return Inliers(points, remaining, FitPlane(points, best), distance);  // refined
}

// Median distance to the nearest other point, from up to 200 of them (2D, plane coordinates).
double MedianSpacing(const std::vector<Eigen::Vector2d>& uv) {
  std::vector<double> nearest;
  const size_t step = std::max<size_t>(1, uv.size() / 200);
  for (size_t i = 0; i < uv.size(); i += step) {
    double best = 1e300;
    for (size_t j = 0; j < uv.size(); ++j) {
      if (j != i) best = std::min(best, (uv[i] - uv[j]).squaredNorm());
    }
    nearest.push_back(std::sqrt(best));
  }
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  return nearest[nearest.size() / 2];
}

// Connected groups of occupied cells → convex hulls of their points, as triangles.
std::vector<Eigen::Vector3f> PatchTriangles(const std::vector<Eigen::Vector3d>& inlier_points, const PlaneFit& plane,
                                            const PlaneProxyOptions& options) {
  const Eigen::Vector3d u = plane.normal.unitOrthogonal();
  const Eigen::Vector3d v = plane.normal.cross(u);
  const Eigen::Vector3d origin = -plane.offset * plane.normal;
  std::vector<Eigen::Vector2d> uv;
  uv.reserve(inlier_points.size());
  for (const auto& p : inlier_points) uv.emplace_back((p - origin).dot(u), (p - origin).dot(v));
  const double cell = std::max(options.cell_spacings * MedianSpacing(uv), 1e-9);
  Eigen::Vector2d lo = uv[0];
  for (const auto& q : uv) lo = lo.cwiseMin(q);
  std::map<std::pair<long, long>, std::vector<int>> cells;
  for (size_t i = 0; i < uv.size(); ++i) {
    cells[{std::lround(std::floor((uv[i].x() - lo.x()) / cell)), std::lround(std::floor((uv[i].y() - lo.y()) / cell))}]
        .push_back(static_cast<int>(i));
  }
  std::map<std::pair<long, long>, int> component;
  std::vector<Eigen::Vector3f> triangles;
  for (const auto& [key, members] : cells) {
    if (component.count(key)) continue;
    // Flood fill over 8-neighbours.
    std::vector<std::pair<long, long>> stack{key};
    std::vector<int> group;
    component[key] = 1;
    while (!stack.empty()) {
      const auto c = stack.back();
      stack.pop_back();
      const auto& here = cells.at(c);
      group.insert(group.end(), here.begin(), here.end());
      for (long dx = -1; dx <= 1; ++dx)
        for (long dy = -1; dy <= 1; ++dy) {
          const std::pair<long, long> n{c.first + dx, c.second + dy};
          if (cells.count(n) && !component.count(n)) {
            component[n] = 1;
            stack.push_back(n);
          }
        }
    }
    if (static_cast<int>(group.size()) < options.min_component_points) continue;
    std::vector<cv::Point2f> flat;
    for (int i : group) flat.emplace_back(static_cast<float>(uv[i].x()), static_cast<float>(uv[i].y()));
    std::vector<cv::Point2f> hull;
    cv::convexHull(flat, hull);
    if (hull.size() < 3) continue;
    auto lift = [&](const cv::Point2f& q) { return (origin + q.x * u + q.y * v).cast<float>().eval(); };
    for (size_t k = 1; k + 1 < hull.size(); ++k) {
      triangles.push_back(lift(hull[0]));
      triangles.push_back(lift(hull[k]));
      triangles.push_back(lift(hull[k + 1]));
    }
  }
  return triangles;
}

}  // namespace

std::vector<Eigen::Vector3f> SceneProxy::Triangles() const {
  std::vector<Eigen::Vector3f> all;
  for (const ProxyPatch& patch : patches) all.insert(all.end(), patch.triangles.begin(), patch.triangles.end());
  return all;
}

void SceneProxy::RemovePlane(const Eigen::Vector3d& normal, double offset, double max_angle_deg, double max_distance) {
  const Eigen::Vector3d n = normal.normalized();
  const double cos_max = std::cos(max_angle_deg * M_PI / 180);
  std::erase_if(patches, [&](const ProxyPatch& p) {
    const double c = p.normal.dot(n);
    if (std::abs(c) < cos_max) return false;
    // Compare offsets with the normals aligned.
    const double o = c > 0 ? p.offset : -p.offset;
    return std::abs(o - offset) <= max_distance;
  });
}

SceneProxy BuildPlaneProxy(const std::vector<Eigen::Vector3d>& points, const PlaneProxyOptions& options) {
  if (points.size() < 3) throw std::invalid_argument("scene proxy: fewer than 3 map points");
  const double distance = options.inlier_fraction * RobustExtent(points);
  std::mt19937_64 rng(options.seed);
  std::vector<int> remaining(points.size());
  for (size_t i = 0; i < points.size(); ++i) remaining[i] = static_cast<int>(i);
  SceneProxy proxy;
  for (int k = 0; k < options.max_planes; ++k) {
    const std::vector<int> inliers = RansacPlane(points, remaining, distance, options.iterations, rng);
    if (static_cast<int>(inliers.size()) < options.min_plane_points) break;
    const PlaneFit plane = FitPlane(points, inliers);
    std::vector<Eigen::Vector3d> on_plane;
    for (int i : inliers) on_plane.push_back(points[i] - (plane.normal.dot(points[i]) + plane.offset) * plane.normal);
    ProxyPatch patch{plane.normal, plane.offset, static_cast<int>(inliers.size()), PatchTriangles(on_plane, plane, options)};
    if (!patch.triangles.empty()) proxy.patches.push_back(std::move(patch));
    std::vector<int> rest;
    std::set_difference(remaining.begin(), remaining.end(), inliers.begin(), inliers.end(), std::back_inserter(rest));
    remaining = std::move(rest);
  }
  return proxy;
}

}  // namespace arview::room
