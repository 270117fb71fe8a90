// The floor search of the map's metric frame (mapping/floor_search.h): the dominant plane of the
// map's points under its cameras, then lower planes for as long as the points below hold one,
// down to the lowest dense plane; and the frame standing on the floor found. Apart from the fits
// that stand on it (mapping/metric_frame.cpp).

#include "mapping/floor_search.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/error.h"
#include "base/stats.h"

namespace arview::mapping {
namespace {

constexpr double kDeg = M_PI / 180;

// The floor is the lowest plane the points hold: below it there are only points matched wrongly,
// too few or too scattered to hold a plane of this share of the points. A horizontal slice through
// densely textured walls holds as many points as a sparsely textured floor (the rendered venue's
// rooms: 452 points in a slice at 1.3 m against the floor's 54 near the cloud's middle), but
// has the walls' lower part and the floor below it.
constexpr double kFloorShareOfPoints = 0.01;
constexpr int kFloorLeastPoints = 30;
// A room has a few such slices (the walls' panels, a table) above its floor.
constexpr int kFloorRounds = 12;
// Below the first plane, one nearly perpendicular to up (the camera centres' plane gives up to a
// fraction of a degree): a plane tilted across the walls holds many of their points. Where up is
// further off, no lower plane is found, and the first one is checked as the floor.
constexpr double kLowerFloorMaxTiltDeg = 5;

int PointsWithin(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double distance) {
  int within = 0;
  for (const Eigen::Vector3d& p : points) within += std::abs(plane.Distance(p)) < distance;
  return within;
}

// Whether `plane`'s normal is within `max_tilt_deg` of `up` either way. FitDominantPlane's
// least-squares refit on its inliers can turn a plane that passed the tilt limit upright (a strip
// of points along a wall's foot).
bool Upright(const Plane& plane, const Eigen::Vector3d& up, double max_tilt_deg) {
  return std::abs(plane.normal.dot(up)) >= std::cos(max_tilt_deg * kDeg);
}

// `plane` with its normal along `up`.
Plane FacingUp(Plane plane, const Eigen::Vector3d& up) {
  if (plane.normal.dot(up) < 0) {
    plane.normal = -plane.normal;
    plane.offset = -plane.offset;
  }
  return plane;
}

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
  PlaneFitOptions options;
  // The first fit's inlier distance (1 % of the cloud's extent) for every fit: a subset's own
  // extent is smaller.
  options.inlier_distance = 0.01 * 2 * MedianDistance(points, ComponentMedian(points));
  const int least = std::max(kFloorLeastPoints, static_cast<int>(kFloorShareOfPoints * points.size()));
  Plane floor;
  Eigen::Vector3d up;
  PlaneFitOptions lower_options = options;  // below the first plane: see kLowerFloorMaxTiltDeg
  try {
    floor = FitFloorUnderCameras(points, Centres(map), up_axes, options, &up);
    lower_options.up_prior = up;
    lower_options.max_tilt_deg = kLowerFloorMaxTiltDeg;
    lower_options.iterations = 2000;
    if (!Upright(floor, up, options.max_tilt_deg)) floor = FitFloorUnderCameras(points, Centres(map), up_axes, lower_options);
  } catch (const Error& e) {
    throw map::MapError(std::string("no floor found in the map's points: ") + e.what());
  }
  if (!Upright(floor, up, options.max_tilt_deg)) {
    throw map::MapError("no floor found in the map's points: the planes near-perpendicular to the cameras' up hold too "
                        "few of them");
  }
  std::vector<Eigen::Vector3d> candidates = points;
  for (int round = 0; round < kFloorRounds; ++round) {
    const Plane facing_up = FacingUp(floor, up);
    std::vector<Eigen::Vector3d> under;  // of the points below the planes before (a plane tilted
    for (const Eigen::Vector3d& p : candidates)  // across a large room would lift the search again)
      if (facing_up.Distance(p) < -options.inlier_distance) under.push_back(p);
    if (static_cast<int>(under.size()) < least) break;
    Plane lower;
    try {
      lower = FitFloorUnderCameras(under, Centres(map), up_axes, lower_options);
    } catch (const Error&) {
      break;  // nothing below holds a plane
    }
    if (!Upright(lower, up, 2 * kLowerFloorMaxTiltDeg) || PointsWithin(lower, points, options.inlier_distance) < least) break;
    floor = lower;
    candidates = std::move(under);
  }
  if (below) {
    const Plane facing_up = FacingUp(floor, up);
    std::size_t count = 0;
    for (const Eigen::Vector3d& p : points) count += facing_up.Distance(p) < -3 * options.inlier_distance;
    *below = static_cast<double>(count) / std::max<std::size_t>(points.size(), 1);
  }
  return floor;
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
