#include "anim/character_bounds.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "anim/pose.h"

namespace arview::anim {

namespace {

std::vector<Eigen::Vector3d> MeshPoints(const Character& c) {
  std::vector<Eigen::Vector3d> points;
  for (const anim::Mesh& m : c.meshes) {
    for (const Eigen::Vector3f& p : m.positions) points.push_back(p.cast<double>());
  }
  return points;
}

std::vector<Eigen::Vector3d> JointPoints(const Character& c) {
  std::vector<Eigen::Vector3d> points;
  if (c.skeleton.size() == 0) return points;
  const anim::LocalPose rest = anim::LocalPose::Rest(c.skeleton);
  std::vector<Eigen::Matrix4d> model(c.skeleton.size());
  anim::MustRun(anim::LocalToModelJob{&c.skeleton, &rest, model}, "character bounds");
  for (const Eigen::Matrix4d& m : model) points.push_back(m.block<3, 1>(0, 3));
  return points;
}

double Extent(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Eigen::Vector3d& p : points) {
    lo = std::min(lo, up.dot(p));
    hi = std::max(hi, up.dot(p));
  }
  return hi > lo ? hi - lo : 0.0;
}

}  // namespace

double RestHeight(const Character& c, const Eigen::Vector3d& up_axis) {
  const Eigen::Vector3d up = up_axis.normalized();
  const double meshes = Extent(MeshPoints(c), up);
  return meshes > 0 ? meshes : Extent(JointPoints(c), up);
}

double RestHeightInMap(const Character& character, const Placement& placement) {
  return RestHeight(character, placement.up) * placement.scale * placement.anchor.scale;
}

RestBox RestBoxOf(const Character& c) {
  RestBox box{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
              Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  std::vector<Eigen::Vector3d> points = MeshPoints(c);
  if (points.empty()) points = JointPoints(c);
  for (const Eigen::Vector3d& p : points) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  }
  return box;
}

}  // namespace arview::anim
