#include "anim/placed_character.h"

#include <utility>

#include "anim/pose.h"

namespace arview::anim {

PlacedCharacter::PlacedCharacter(PlacedCharacterParts parts)
    : parts_(std::move(parts)), buffers_(parts_.character->skeleton) {}

const AnimatorFrame& PlacedCharacter::Update(const Eigen::Vector3d& viewpoint, double time_seconds) {
  const Skeleton& sk = parts_.character->skeleton;
  FrameInputs inputs;
  inputs.viewpoint = viewpoint;
  if (!parts_.blend->Sample(time_seconds, inputs, buffers_.local[0]))
    throw Error(parts_.where + ": view-adaptive blend: key clips and skeleton disagree");
  buffers_.Finish(sk, frame_, "local to model", "skinning matrices");
  frame_.key_weights = parts_.blend->weights();
  frame_.converged = parts_.blend->converged();
  frame_.max_iterations = parts_.blend->max_iterations();
  frame_.view_gain = 1;
  frame_.viewpoint = viewpoint;
  return frame_;
}

}  // namespace arview::anim
