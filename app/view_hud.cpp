#include "app/view_hud.h"

#include "app/view_animation.h"

namespace arview::app {

render::HudSphere HudSphereFor(const anim::CharacterSpec& spec, std::span<const double> weights,
                               const Eigen::Vector3d& viewpoint, double height, int highlighted_key) {
  render::HudSphere s;
  s.name = spec.name;
  s.centre = spec.anchor.position;
  s.rotation = spec.anchor.rotation.normalized();
  s.forward = spec.forward;
  s.up = spec.up;
  s.radius = 1.1 * height;
  s.viewpoint = viewpoint;
  for (size_t k = 0; k < spec.keys.size(); ++k) {
    render::HudKey key;
    key.direction = spec.keys[k].viewpoint;
    key.weight = k < weights.size() ? weights[k] : 0;
    key.label = KeySourceLabel(spec.keys[k]);
    key.highlighted = static_cast<int>(k) == highlighted_key;
    s.keys.push_back(key);
  }
  return s;
}

}  // namespace arview::app
