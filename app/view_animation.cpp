#include "app/view_animation.h"

#include <cstdio>

#include "app/character_bounds.h"

namespace arview::app {

std::string KeySourceLabel(const anim::KeySpec& key) {
  switch (key.source) {
    case anim::KeySpec::Source::kClip: return key.clip;
    case anim::KeySpec::Source::kLookAt: return "lookat";
    case anim::KeySpec::Source::kRestPose: return "rest";
    case anim::KeySpec::Source::kStaticPose: {
      char t[32];
      std::snprintf(t, sizeof t, "@%g", key.pose_time);
      return key.clip + t;
    }
  }
  return "?";
}

ViewAnimation::ViewAnimation(const anim::CharacterSpec& spec) : spec_(spec) {
  auto first = std::make_unique<anim::AnimatedCharacter>(spec_);
  asset_ = first->shared_character();
  character_ = std::move(first);
  animator_ = std::make_unique<LayeredAnimator>(*character_);
  height_ = RestHeight(*asset_, spec_.up) * spec_.scale * spec_.anchor.scale;
  if (!(height_ > 0)) height_ = 1;
}

void ViewAnimation::SetKeys(const std::vector<anim::KeySpec>& keys) {
  anim::CharacterSpec next = spec_;
  next.keys = keys;
  auto rebuilt = std::make_unique<anim::AnimatedCharacter>(asset_, next);  // throws: old keys stay
  animator_.reset();
  character_ = std::move(rebuilt);
  animator_ = std::make_unique<LayeredAnimator>(*character_);
  spec_.keys = keys;
}

const anim::FrameOutput& ViewAnimation::Update(const Eigen::Vector3d& camera_center_map, double time) {
  const AnimatedFrame& f = animator_->Update(camera_center_map, time);
  viewpoint_ = f.viewpoint;
  out_.weights = f.key_weights;
  out_.model = f.model;
  out_.skinning_matrices = f.skinning_matrices;
  out_.skinning_dual_quats = f.skinning_dual_quats;
  return out_;
}

std::string ViewAnimation::KeyLabel(int key) const { return KeySourceLabel(spec_.keys.at(key)); }

}  // namespace arview::app
