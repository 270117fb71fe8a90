#include "app/placement/placement.h"

#include <Eigen/Dense>

#include <algorithm>

namespace arview::app {

namespace {

// Character frame (glTF): +Y up, +Z forward, +X = up × forward (the character's left). Facing
// `towards` projected onto the plane across `up`; any perpendicular when it is straight above.
Eigen::Quaterniond UprightFacing(const Eigen::Vector3d& up, const Eigen::Vector3d& position,
                                 const Eigen::Vector3d& towards) {
  Eigen::Vector3d forward = towards - position;
  forward -= forward.dot(up) * up;
  if (forward.norm() < 1e-9) forward = up.unitOrthogonal();
  forward.normalize();
  Eigen::Matrix3d rotation;
  rotation << up.cross(forward), up, forward;
  return Eigen::Quaterniond(rotation).normalized();
}

}  // namespace

Anchor PlaceOnFloor(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, double character_height,
                            const PlacementOptions& o) {
  if (camera_centres.empty()) throw PlacementError("the map has no registered cameras");
  if (!(character_height > 0)) throw PlacementError("the character has no height (empty or flat bind pose)");
  // The lowest dense plane, not the densest: a slice through densely textured walls, or a table,
  // can hold more points than the floor.
  const LowestFloor found = [&] {
    try {
      return FindLowestFloor(points, camera_centres, camera_up_axes, o.plane);
    } catch (const Error& e) {  // the map's points, said as a placement error (the caller names the map)
      throw PlacementError(e.what());
    }
  }();
  const Plane& plane = found.floor;
  const Eigen::Vector3d& camera_up = found.up;

  // Stand at the median of the plane's inliers near the middle, projected onto the plane.
  std::vector<Eigen::Vector3d> on_plane;
  for (const auto& p : points) {
    if (std::abs(plane.Distance(p)) < found.inlier_distance) on_plane.push_back(p);
  }
  Eigen::Vector3d position = on_plane.empty() ? ComponentMedian(points) : ComponentMedian(on_plane);
  position -= plane.Distance(position) * plane.normal;

  // Face the first keyframe. Stand upright in the viewers' world: up is the cameras' up (signed
  // like the floor's normal); the floor gives the footing. On a level floor the two agree within
  // the RANSAC noise.
  Anchor anchor;
  anchor.position = position;
  anchor.rotation = UprightFacing(camera_up.dot(plane.normal) < 0 ? -camera_up : camera_up, position,
                                  camera_centres.front());
  anchor.scale = o.height_fraction * MedianDistance(camera_centres, position) / character_height;
  return anchor;
}

Anchor StandAt(const Anchor& on_floor, const Eigen::Vector3d& at, const Eigen::Vector3d& towards) {
  const Eigen::Vector3d up = (on_floor.rotation * Eigen::Vector3d::UnitY()).normalized();
  Anchor anchor = on_floor;
  anchor.position = at - (at - on_floor.position).dot(up) * up;
  anchor.rotation = UprightFacing(up, anchor.position, towards);
  return anchor;
}

Anchor StandInFrontOfView(const Anchor& on_floor, double height, const Eigen::Vector3d& camera_centre,
                          const Eigen::Vector3d& view_direction) {
  const Eigen::Vector3d up = (on_floor.rotation * Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d view = view_direction.normalized();
  // The view's direction along the floor (looking straight down, any direction serves).
  Eigen::Vector3d along = view - view.dot(up) * up;
  along = along.norm() < 1e-6 ? up.unitOrthogonal() : along.normalized();
  // Where the line of sight meets the floor, as a distance along the floor from the point under
  // the camera; a camera looking level or up never meets it: the far limit.
  const Eigen::Vector3d to_middle = on_floor.position - camera_centre;
  const double camera_height = -to_middle.dot(up);
  const double near = kFirstViewDistanceInHeights[0] * height;
  const double far = std::max(near, std::min(kFirstViewDistanceInHeights[1] * height,
                                             (to_middle - to_middle.dot(up) * up).norm()));
  const double down = -view.dot(up);
  double distance = far;
  if (down > 1e-6 && camera_height > 0) distance = camera_height / down * view.dot(along);
  distance = std::clamp(distance, near, far);
  return StandAt(on_floor, camera_centre + distance * along, camera_centre);
}

}  // namespace arview::app
