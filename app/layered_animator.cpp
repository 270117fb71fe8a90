#include "app/layered_animator.h"

#include <algorithm>

namespace arview::app {

LayeredAnimator::LayeredAnimator(anim::AnimatedCharacter& character, const std::string& idle_clip,
                                 const FadeOptions& options)
    : character_(character), options_(options) {
  const anim::Character& c = character.character();
  if (!idle_clip.empty()) {
    idle_ = c.FindClip(idle_clip);
    if (!idle_) throw anim::Error(c.source + ": has no clip '" + idle_clip + "' for the idle layer");
  } else if (character.spec().lookat.base_clip == "rest") {
    idle_ = c.FindClip("rest");  // usually none: the idle layer is then the rest pose
  } else {
    if (!character.spec().lookat.base_clip.empty()) idle_ = c.FindClip(character.spec().lookat.base_clip);
    if (!idle_ && !c.clips.empty()) idle_ = &c.clips.front();
  }
  const int n = c.skeleton.size();
  idle_pose_ = anim::LocalPose::Rest(c.skeleton);
  idle_model_.resize(n);
  mixed_model_.resize(n);
  skin_.resize(n);
  skin_dq_.resize(n);
}

const AnimatedFrame& LayeredAnimator::Update(const std::optional<Eigen::Vector3d>& camera_center, double time) {
  const double dt = last_time_ ? std::max(0.0, time - *last_time_) : 0.0;
  last_time_ = time;
  const double fade_step = options_.fade_seconds > 0 ? dt / options_.fade_seconds : 1.0;
  if (camera_center) {
    const Eigen::Vector3d v = character_.spec().ViewpointFromCamera(*camera_center);
    if (v.squaredNorm() > 0) last_viewpoint_ = v;
    lost_since_.reset();
    idle_weight_ = std::max(0.0, idle_weight_ - fade_step);
  } else {
    if (!lost_since_) lost_since_ = time;
    if (time - *lost_since_ >= options_.hold_seconds) idle_weight_ = std::min(1.0, idle_weight_ + fade_step);
  }

  const anim::FrameOutput& adaptive = character_.Update(last_viewpoint_, time);
  frame_.key_weights = adaptive.weights;
  frame_.viewpoint = last_viewpoint_;
  frame_.idle_weight = idle_weight_;
  if (idle_weight_ <= 0) {
    frame_.skinning_matrices = adaptive.skinning_matrices;
    frame_.skinning_dual_quats = adaptive.skinning_dual_quats;
    frame_.model = adaptive.model;
    return frame_;
  }
  MixWithIdle(adaptive.model, idle_weight_);
  frame_.skinning_matrices = skin_;
  frame_.skinning_dual_quats = skin_dq_;
  frame_.model = mixed_model_;
  return frame_;
}

void LayeredAnimator::MixWithIdle(std::span<const Eigen::Matrix4d> adaptive, double w) {
  const anim::Skeleton& skeleton = character_.character().skeleton;
  if (idle_) anim::MustRun(anim::SamplingJob{&skeleton, idle_, last_time_.value_or(0), true, &idle_pose_}, "idle layer");
  anim::MustRun(anim::LocalToModelJob{&skeleton, &idle_pose_, idle_model_}, "idle layer");
  for (size_t j = 0; j < mixed_model_.size(); ++j) {
    const anim::Transform a = anim::Transform::FromMatrix(adaptive[j]);
    const anim::Transform b = anim::Transform::FromMatrix(idle_model_[j]);
    anim::Transform m;
    m.translation = (1 - w) * a.translation + w * b.translation;
    m.rotation = a.rotation.slerp(w, b.rotation);
    m.scale = (1 - w) * a.scale + w * b.scale;
    mixed_model_[j] = m.ToMatrix();
  }
  anim::MustRun(anim::SkinningMatricesJob{&skeleton, mixed_model_, skin_, skin_dq_}, "idle layer");
}

}  // namespace arview::app
