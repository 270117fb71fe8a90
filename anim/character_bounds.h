#pragma once
// The extent of a character's rest pose along its up axis, in asset units: from its meshes, or
// from its joints when it has no skin (BVH).

#include <Eigen/Core>

#include "anim/character.h"

namespace arview::anim {

double RestHeight(const Character& character, const Eigen::Vector3d& up);

}  // namespace arview::anim
