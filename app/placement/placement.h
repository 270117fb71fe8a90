#pragma once
// Where a character stands in a map: the dominant plane of the map's points near the middle of
// the scene (RANSAC), the character's up along the plane normal towards the cameras, facing the
// first keyframe, scaled to the scene.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "base/error.h"
#include "base/geometry.h"
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
// the dominant plane among those within options.plane.max_tilt_deg of UpFromCameras().
Anchor PlaceOnDominantPlane(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, double character_height,
                            const PlacementOptions& options);

}  // namespace arview::app
