#pragma once
// The extent of a character's rest pose along its up axis, in asset units: from its meshes, or
// from its joints when it has no skin (BVH).

#include <Eigen/Core>

#include "anim/character.h"
#include "anim/placement.h"

namespace arview::anim {

double RestHeight(const Character& character, const Eigen::Vector3d& up);

// The same extent in map units, for a character standing at `placement` (the overlay's sphere
// is sized from it).
double RestHeightInMap(const Character& character, const Placement& placement);

}  // namespace arview::anim
