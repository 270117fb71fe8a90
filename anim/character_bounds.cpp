#include "anim/character_bounds.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "anim/pose.h"

namespace arview::anim {

double RestHeight(const Character& c, const Eigen::Vector3d& up_axis) {
  const Eigen::Vector3d up = up_axis.normalized();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const anim::Mesh& m : c.meshes) {
    for (const Eigen::Vector3f& p : m.positions) {
      const double h = up.dot(p.cast<double>());
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  }
  if (hi > lo) return hi - lo;
  const anim::LocalPose rest = anim::LocalPose::Rest(c.skeleton);
  std::vector<Eigen::Matrix4d> model(c.skeleton.size());
  anim::MustRun(anim::LocalToModelJob{&c.skeleton, &rest, model}, "character bounds");
  for (const Eigen::Matrix4d& m : model) {
    const double h = up.dot(m.block<3, 1>(0, 3));
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  return hi > lo ? hi - lo : 0.0;
}

double RestHeightInMap(const Character& character, const Placement& placement) {
  return RestHeight(character, placement.up) * placement.scale * placement.anchor.scale;
}

}  // namespace arview::anim
