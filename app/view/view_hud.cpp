#include "app/view/view_hud.h"

#include <vector>

namespace arview::app {

render::HudSphere HudSphereFor(const authoring::CharacterSpec& spec, std::span<const double> weights,
                               const Eigen::Vector3d& viewpoint, double height, int highlighted_key) {
  // The keys as the scene being edited holds them now (`arview view` adds and removes keys).
  std::vector<Eigen::Vector3d> directions;
  std::vector<std::string> labels;
  for (const authoring::KeySpec& key : spec.keys) {
    directions.push_back(key.viewpoint);
    labels.push_back(authoring::KeySourceLabel(key));
  }
  return render::HudSphereFor(spec.placement(), spec.name, directions, labels, weights, viewpoint, height,
                              highlighted_key);
}

}  // namespace arview::app
