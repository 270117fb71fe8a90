#include "app/pipeline/layered_animator.h"

#include <utility>

#include "base/error.h"

namespace arview::app {

void FadeOptions::Check(const OptionNames& names) const {
  RequireOption(hold_seconds >= 0, names("hold_seconds"), "0 or more", hold_seconds);
  RequireOption(fade_seconds >= 0, names("fade_seconds"), "0 or more", fade_seconds);
}

LayeredAnimator::LayeredAnimator(const anim::PlacedCharacter& character, std::unique_ptr<anim::Animator> animator,
                                 const anim::Clip* idle_clip, std::vector<std::string> notes)
    : character_(character), idle_(idle_clip), animator_(std::move(animator)), notes_(std::move(notes)) {}

void LayeredAnimator::SetDialogue(std::unique_ptr<CharacterDialogue> dialogue) {
  if (dialogue && !speech_) throw Error("dialogue: the character has no speech to answer with (SetSpeech first)");
  dialogue_ = std::move(dialogue);
}

const anim::AnimatorFrame& LayeredAnimator::Update(const std::optional<Eigen::Vector3d>& camera_center, double time,
                                                   const std::optional<Eigen::Vector3d>& optical_axis) {
  const anim::Placement& placement = character_.placement();
  anim::FrameInputs inputs;
  inputs.tracking = camera_center.has_value();
  if (camera_center) {
    inputs.viewpoint = placement.ViewpointFromCamera(*camera_center);
    inputs.distance = placement.FloorDistance(*camera_center);
    inputs.viewer = placement.MapToModel(*camera_center);
  } else {
    inputs.viewpoint = Eigen::Vector3d::Zero();  // held by the animator
  }
  if (!speech_) return animator_->Update(time, inputs);
  SpeechCues cues;
  cues.tracking = inputs.tracking;
  if (camera_center) {
    cues.distance = inputs.distance;
    cues.viewpoint = inputs.viewpoint;
  }
  if (dialogue_) {
    dialogue_->Update(time, placement, camera_center, optical_axis, *speech_, *animator_);
    inputs.pause_offset_scale = dialogue_->frame().pause_offset_scale;  // the emotion's pace of the idle
  }
  const anim::FaceTrack& face = speech_->Update(time, cues, *animator_);
  const anim::AnimatorFrame& frame = animator_->Update(time, inputs, &face);
  if (dialogue_) dialogue_->ShowExpression(*animator_, frame);
  return frame;
}

}  // namespace arview::app
