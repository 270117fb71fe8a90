#include "app/placement/placement.h"

#include <Eigen/Dense>

#include <algorithm>

namespace arview::app {

Anchor PlaceOnDominantPlane(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, double character_height,
                            const PlacementOptions& o) {
  if (camera_centres.empty()) throw PlacementError("the map has no registered cameras");
  if (!(character_height > 0)) throw PlacementError("the character has no height (empty or flat bind pose)");
  Eigen::Vector3d camera_up;
  const Plane plane = [&] {
    try {
      return FitFloorUnderCameras(points, camera_centres, camera_up_axes, o.plane, &camera_up);
    } catch (const Error& e) {  // the map's points, said as a placement error (the caller names the map)
      throw PlacementError(e.what());
    }
  }();

  // Stand at the median of the plane's inliers near the middle, projected onto the plane.
  const Eigen::Vector3d middle = ComponentMedian(points);
  const double limit = o.plane.inlier_distance > 0 ? o.plane.inlier_distance : 0.01 * 2 * MedianDistance(points, middle);
  std::vector<Eigen::Vector3d> on_plane;
  for (const auto& p : points) {
    if (std::abs(plane.Distance(p)) < limit) on_plane.push_back(p);
  }
  Eigen::Vector3d position = on_plane.empty() ? middle : ComponentMedian(on_plane);
  position -= plane.Distance(position) * plane.normal;

  // Face the first keyframe: its direction projected onto the plane (any perpendicular if above).
  // Stand upright in the viewers' world: up is the cameras' up (signed like the floor's normal);
  // the floor gives the footing. On a level floor the two agree within the RANSAC noise.
  Eigen::Vector3d up = camera_up;
  if (up.dot(plane.normal) < 0) up = -up;
  Eigen::Vector3d forward = camera_centres.front() - position;
  forward -= forward.dot(up) * up;
  if (forward.norm() < 1e-9) forward = up.unitOrthogonal();
  forward.normalize();
  const Eigen::Vector3d right = up.cross(forward);  // glTF: +X = up × forward (character's left)

  Eigen::Matrix3d rotation;
  rotation << right, up, forward;
  Anchor anchor;
  anchor.position = position;
  anchor.rotation = Eigen::Quaterniond(rotation).normalized();
  anchor.scale = o.height_fraction * MedianDistance(camera_centres, position) / character_height;
  return anchor;
}

}  // namespace arview::app
