// The lowest dense plane under a scene's cameras (base/lowest_floor.h): the dominant plane first,
// then lower planes for as long as the points below hold one.

#include "base/lowest_floor.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"

namespace arview {
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

}  // namespace

LowestFloor FindLowestFloor(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, PlaneFitOptions options) {
  // The first fit's inlier distance (1 % of the cloud's extent) for every fit: a subset's own
  // extent is smaller.
  if (!(options.inlier_distance > 0)) options.inlier_distance = 0.01 * 2 * MedianDistance(points, ComponentMedian(points));
  const int least = std::max(kFloorLeastPoints, static_cast<int>(kFloorShareOfPoints * points.size()));
  LowestFloor found;
  found.inlier_distance = options.inlier_distance;
  found.floor = FitFloorUnderCameras(points, camera_centres, camera_up_axes, options, &found.up);
  PlaneFitOptions lower_options = options;  // below the first plane: see kLowerFloorMaxTiltDeg
  lower_options.up_prior = found.up;
  lower_options.max_tilt_deg = kLowerFloorMaxTiltDeg;
  lower_options.iterations = std::max(options.iterations, 2000);
  if (!Upright(found.floor, found.up, options.max_tilt_deg))
    found.floor = FitFloorUnderCameras(points, camera_centres, camera_up_axes, lower_options);
  if (!Upright(found.floor, found.up, options.max_tilt_deg))
    throw Error("the planes near-perpendicular to the cameras' up hold too few of them");

  std::vector<Eigen::Vector3d> candidates = points;
  for (int round = 0; round < kFloorRounds; ++round) {
    const Plane facing_up = FacingUp(found.floor, found.up);
    std::vector<Eigen::Vector3d> under;  // of the points below the planes before (a plane tilted
    for (const Eigen::Vector3d& p : candidates)  // across a large room would lift the search again)
      if (facing_up.Distance(p) < -options.inlier_distance) under.push_back(p);
    if (static_cast<int>(under.size()) < least) break;
    Plane lower;
    try {
      lower = FitFloorUnderCameras(under, camera_centres, camera_up_axes, lower_options);
    } catch (const Error&) {
      break;  // nothing below holds a plane
    }
    if (!Upright(lower, found.up, 2 * kLowerFloorMaxTiltDeg) || PointsWithin(lower, points, options.inlier_distance) < least)
      break;
    found.floor = lower;
    candidates = std::move(under);
  }
  const Plane facing_up = FacingUp(found.floor, found.up);
  std::size_t under_floor = 0;
  for (const Eigen::Vector3d& p : points) under_floor += facing_up.Distance(p) < -3 * options.inlier_distance;
  found.below_share = static_cast<double>(under_floor) / std::max<std::size_t>(points.size(), 1);
  return found;
}

}  // namespace arview
