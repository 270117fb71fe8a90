#pragma once
// The floor under a scene's cameras as the lowest dense plane of its points, not the densest
// one: a horizontal slice through densely textured walls holds more points than a plain floor
// (the rendered venue's rooms), and a table stands above the floor. The map's metric frame
// (mapping/floor_search.h) and the character's placement (app/placement) stand on it.

#include <vector>

#include <Eigen/Core>

#include "base/plane_fit.h"

namespace arview {

struct LowestFloor {
  Plane floor;                                  // its normal as FitFloorUnderCameras turns it: towards the cameras
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // the cameras' up the search went down along
  double below_share = 0;                       // the points more than three inlier distances under it
  double inlier_distance = 0;                   // a point this close to a plane lies on it (every fit's)
};

// The dominant plane of `points` under the cameras (FitFloorUnderCameras, within
// options.max_tilt_deg of their up); then, while the points below the plane found hold another
// plane near-perpendicular to up of at least 1 % of the points (and 30), that one, down to the
// lowest. options.inlier_distance 0: 1 % of the whole cloud's robust extent, for every fit.
// Throws arview::Error when no plane near-perpendicular to up holds enough points (said without
// naming the cloud: the caller names it).
LowestFloor FindLowestFloor(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, PlaneFitOptions options = {});

}  // namespace arview
