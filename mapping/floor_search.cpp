// The floor of the map's metric frame (mapping/floor_search.h): base/lowest_floor.h's search on
// the map's points and cameras, and the frame standing on the floor found. Apart from the fits
// that stand on it (mapping/metric_frame.cpp).

#include "mapping/floor_search.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/error.h"
#include "base/lowest_floor.h"
#include "base/stats.h"

namespace arview::mapping {
namespace {

Eigen::Vector3d Mean(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : points) sum += p;
  return sum / std::max<std::size_t>(points.size(), 1);
}

}  // namespace

std::vector<Eigen::Vector3d> Centres(const map::Map& map) {
  std::vector<Eigen::Vector3d> centres;
  for (const map::Keyframe& k : map.keyframes) centres.push_back(k.pose.Center());
  return centres;
}

Plane FindFloor(const map::Map& map, double* below) {
  std::vector<Eigen::Vector3d> points, up_axes;
  for (const map::MapPoint& p : map.points) points.push_back(p.xyz);
  for (const map::Keyframe& k : map.keyframes) up_axes.push_back(-(k.pose.q_cw.conjugate() * Eigen::Vector3d::UnitY()));
  try {
    const LowestFloor found = FindLowestFloor(points, Centres(map), up_axes);
    if (below) *below = found.below_share;
    return found.floor;
  } catch (const Error& e) {
    throw map::MapError(std::string("no floor found in the map's points: ") + e.what());
  }
}

Sim3 FloorFrame(const map::Map& map, const Plane& floor, double scale) {
  const Eigen::Vector3d z = floor.normal.normalized();
  Eigen::Vector3d x = map.keyframes.front().pose.q_cw.conjugate() * Eigen::Vector3d::UnitZ();
  x -= x.dot(z) * z;
  if (x.norm() < 1e-6) x = z.unitOrthogonal();
  x.normalize();
  Eigen::Matrix3d axes;  // rows: the new frame's axes in map coordinates
  axes.row(0) = x;
  axes.row(1) = z.cross(x);
  axes.row(2) = z;
  const Eigen::Vector3d centre = Mean(Centres(map));
  const Eigen::Vector3d origin = centre - floor.Distance(centre) * z;
  Sim3 s;
  s.scale = scale;
  s.R = axes;
  s.t = -scale * (axes * origin);
  return s;
}

double MedianHeightOverFloor(const map::Map& map, const Plane& floor) {
  std::vector<double> heights;
  for (const Eigen::Vector3d& c : Centres(map)) heights.push_back(floor.Distance(c));
  return Median(heights);
}

}  // namespace arview::mapping
