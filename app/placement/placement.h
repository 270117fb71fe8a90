#pragma once
// Where a character stands in a map: on the floor under the cameras (the lowest dense plane of the
// map's points, base/lowest_floor.h), the character's up along the plane normal towards the
// cameras, facing the first keyframe, scaled to the scene.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "base/error.h"
#include "base/geometry.h"
#include "base/lowest_floor.h"
#include "base/plane_fit.h"

namespace arview::app {

struct PlacementError : Error {
  using Error::Error;
};

// The plane fit (FitDominantPlane, Plane, PlaneFitOptions) and the Anchor are base/'s.

struct PlacementOptions {
  PlaneFitOptions plane;
  // The character's height as a fraction of the median distance from the cameras to the anchor.
  double height_fraction = 0.3;
};

// UpFromCameras (which way is up, from the cameras) is base/plane_fit.h's.

// Character frame convention (glTF): +Y up, +Z forward (the direction the character faces).
// `character_height` is the height of the character's bind pose in its own units. The floor is
// FindLowestFloor's: the lowest dense plane within options.plane.max_tilt_deg of
// UpFromCameras().
Anchor PlaceOnFloor(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, double character_height,
                            const PlacementOptions& options);

// The same character moved on its floor: standing where `at` falls on the floor of `on_floor`
// (its position a point of the floor, its up the floor's normal), upright, facing `towards`
// (any direction along the floor if `towards` is straight above or below). The scale is kept.
// `arview place --at --facing` and the first run without a scene (`run`, `replay`) share it.
Anchor StandAt(const Anchor& on_floor, const Eigen::Vector3d& at, const Eigen::Vector3d& towards);

// How far along the floor a character stands from the camera that first sees it, in its own
// heights: where the line of sight meets the floor, held within these (a camera looking level
// or up meets it far away, or never), and no farther than the floor's middle (`place`'s spot)
// when that is nearer, so that it stays in the mapped room.
inline constexpr double kFirstViewDistanceInHeights[2] = {1.0, 2.0};

// Where a character of `height` (map units) stands when put in front of a view: on the floor of
// `on_floor` where the camera at `camera_centre` looking along `view_direction` (map frame)
// sees it, its distance along the floor within kFirstViewDistanceInHeights and no farther than
// `on_floor.position` is from the camera (but at least the near limit), facing the camera.
Anchor StandInFrontOfView(const Anchor& on_floor, double height, const Eigen::Vector3d& camera_centre,
                          const Eigen::Vector3d& view_direction);

}  // namespace arview::app
