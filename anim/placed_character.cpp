#include "anim/placed_character.h"

#include <utility>

#include "anim/pose.h"

namespace arview::anim {

PlacedCharacter::PlacedCharacter(PlacedCharacterParts parts) : parts_(std::move(parts)) {
  const Skeleton& sk = parts_.character->skeleton;
  blended_.assign(1, LocalPose::Rest(sk));
  model_.assign(sk.size(), Eigen::Matrix4d::Identity());
  skin_.assign(sk.size(), Eigen::Matrix4f::Identity());
  skin_dq_.assign(sk.size(), DualQuatf());
}

const AnimatorFrame& PlacedCharacter::Update(const Eigen::Vector3d& viewpoint, double time_seconds) {
  const Skeleton& sk = parts_.character->skeleton;
  FrameInputs inputs;
  inputs.viewpoint = viewpoint;
  if (!parts_.blend->Sample(time_seconds, inputs, blended_.front()))
    throw Error(parts_.where + ": view-adaptive blend: key clips and skeleton disagree");
  MustRun(LocalToModelJob{&sk, &blended_.front(), model_}, "local to model");
  MustRun(SkinningMatricesJob{&sk, model_, skin_, skin_dq_}, "skinning matrices");
  frame_.key_weights = parts_.blend->weights();
  frame_.converged = parts_.blend->converged();
  frame_.max_iterations = parts_.blend->max_iterations();
  frame_.view_gain = 1;
  frame_.viewpoint = viewpoint;
  frame_.local = blended_;
  frame_.model = model_;
  frame_.skinning_matrices = skin_;
  frame_.skinning_dual_quats = skin_dq_;
  return frame_;
}

}  // namespace arview::anim
