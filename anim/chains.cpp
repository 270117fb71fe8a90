#include "anim/chains.h"

namespace arview::anim {

Eigen::Vector3d HeadForward(const LookAtChain& chain, std::span<const Eigen::Matrix4d> model) {
  // The head joint's rotation with its scale taken out (columns normalised).
  Eigen::Matrix3d rotation = model[chain.joints.back()].block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) rotation.col(c).normalize();
  return rotation * chain.head_forward_local;
}

}  // namespace arview::anim
