#include "app/layered_animator.h"

namespace arview::app {

LayeredAnimator::LayeredAnimator(anim::AnimatedCharacter& character, const std::string& idle_clip,
                                 const FadeOptions& options)
    : character_(character) {
  const anim::Character& c = character.character();
  const anim::CharacterSpec& spec = character.spec();
  if (!idle_clip.empty()) {
    idle_ = c.FindClip(idle_clip);
    if (!idle_) throw anim::Error(c.source + ": has no clip '" + idle_clip + "' for the idle layer");
  } else if (!spec.schedule.given && !spec.idle.given && spec.lookat.base_clip != "rest") {
    if (!spec.lookat.base_clip.empty()) idle_ = c.FindClip(spec.lookat.base_clip);
    if (!idle_ && !c.clips.empty()) idle_ = &c.clips.front();
  }
  anim::AnimatorOverrides overrides;
  overrides.idle_clip = idle_clip;
  overrides.hold_seconds = options.hold_seconds;
  overrides.fade_seconds = options.fade_seconds;
  animator_ = anim::BuildAnimator(character, overrides, &notes_);
}

const AnimatedFrame& LayeredAnimator::Update(const std::optional<Eigen::Vector3d>& camera_center, double time) {
  const anim::CharacterSpec& spec = character_.spec();
  anim::FrameInputs inputs;
  inputs.tracking = camera_center.has_value();
  if (camera_center) {
    inputs.viewpoint = spec.ViewpointFromCamera(*camera_center);
    // Along the floor: "the viewer comes within 1.5 m" of a standing character means on the
    // ground, not from the eyes to its feet (at eye height that would be never closer than ~1.6 m).
    const Eigen::Vector3d up = (spec.anchor.rotation * spec.up).normalized();
    const Eigen::Vector3d to_camera = *camera_center - spec.anchor.position;
    inputs.distance = (to_camera - to_camera.dot(up) * up).norm();
  } else {
    inputs.viewpoint = Eigen::Vector3d::Zero();  // held by the animator
  }
  const anim::AnimatorFrame& f = animator_->Update(time, inputs);
  frame_.skinning_matrices = f.skinning_matrices;
  frame_.skinning_dual_quats = f.skinning_dual_quats;
  frame_.model = f.model;
  frame_.key_weights = f.key_weights;
  frame_.viewpoint = f.viewpoint;
  frame_.triggered = f.triggered;
  frame_.idle_weight = animator_->view_action_id() >= 0 ? 1.0 - f.view_gain : 1.0;
  return frame_;
}

}  // namespace arview::app
