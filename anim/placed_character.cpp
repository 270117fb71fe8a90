#include "anim/placed_character.h"

#include <utility>

#include "anim/pose.h"

namespace arview::anim {

PlacedCharacter::PlacedCharacter(PlacedCharacterParts parts)
    : parts_(std::move(parts)), buffers_(parts_.character->skeleton) {
  if (parts_.gaze && parts_.gaze->rig.valid()) gaze_.emplace(parts_.character->skeleton, parts_.gaze->rig, parts_.gaze->options);
}

const AnimatorFrame& PlacedCharacter::Update(const Eigen::Vector3d& viewpoint, double time_seconds, const Eigen::Vector3d& viewer) {
  const Skeleton& sk = parts_.character->skeleton;
  FrameInputs inputs;
  inputs.viewpoint = viewpoint;
  if (!parts_.blend->Sample(time_seconds, inputs, buffers_.local[0]))
    throw Error(parts_.where + ": view-adaptive blend: key clips and skeleton disagree");
  if (gaze_) {
    gaze_->PoseEyes(sk, time_seconds, viewer, buffers_.local[0], buffers_.model);
    frame_.gaze = gaze_->frame();
  }
  buffers_.Finish(sk, frame_, "local to model", "skinning matrices");
  frame_.key_weights = parts_.blend->weights();
  frame_.converged = parts_.blend->converged();
  frame_.max_iterations = parts_.blend->max_iterations();
  frame_.view_gain = 1;
  frame_.viewpoint = viewpoint;
  return frame_;
}

}  // namespace arview::anim
