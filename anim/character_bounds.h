#pragma once
// The extent of a character's rest pose, in asset units: from its meshes, or from its joints
// when it has no skin (BVH).

#include <Eigen/Core>

#include "anim/character.h"
#include "anim/placement.h"

namespace arview::anim {

// Along its up axis.
double RestHeight(const Character& character, const Eigen::Vector3d& up);

// The same extent in map units, for a character standing at `placement` (the overlay's sphere
// is sized from it).
double RestHeightInMap(const Character& character, const Placement& placement);

// The axis-aligned box round the rest pose, model space; min > max (empty) when the character
// has neither vertices nor joints.
struct RestBox {
  Eigen::Vector3d min, max;
  bool empty() const { return !(min.array() <= max.array()).all(); }
};
RestBox RestBoxOf(const Character& character);

}  // namespace arview::anim
