#pragma once
// What the overlay (render/hud.h) shows for a character of a scene: its view sphere (centred on
// its anchor, sized to enclose it), its keys with their weights this frame, and the viewpoint
// the animation used. The scene being edited by `arview view`, through render::HudSphereFor.

#include <Eigen/Core>

#include <span>
#include <string>
#include <vector>

#include "anim_authoring/scene.h"
#include "render/hud.h"

namespace arview::app {

// `height` is the character's rest height in map units: the sphere's radius is 1.1× that.
render::HudSphere HudSphereFor(const authoring::CharacterSpec& spec, std::span<const double> weights,
                               const Eigen::Vector3d& viewpoint, double height, int highlighted_key = -1);

}  // namespace arview::app
