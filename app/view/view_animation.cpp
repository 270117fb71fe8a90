#include "app/view/view_animation.h"

#include <cstdio>

#include "anim_authoring/character_builder.h"
#include "anim/character_bounds.h"
#include "app/session/character_setup.h"

namespace arview::app {

ViewAnimation::ViewAnimation(const authoring::CharacterSpec& spec) : spec_(spec) {
  auto first = std::make_unique<authoring::AnimatedCharacter>(spec_);
  asset_ = first->shared_character();
  character_ = std::move(first);
  animator_ = MakeLayeredAnimator(*character_);
  height_ = anim::RestHeightInMap(*asset_, spec_.placement());
  if (!(height_ > 0)) height_ = 1;
}

void ViewAnimation::SetKeys(const std::vector<authoring::KeySpec>& keys) {
  authoring::CharacterSpec next = spec_;
  next.keys = keys;
  auto rebuilt = std::make_unique<authoring::AnimatedCharacter>(asset_, next);  // throws: old keys stay
  animator_.reset();
  character_ = std::move(rebuilt);
  animator_ = MakeLayeredAnimator(*character_);
  spec_.keys = keys;
}

const anim::AnimatorFrame& ViewAnimation::Update(const Eigen::Vector3d& camera_center_map, double time) {
  const anim::AnimatorFrame& f = animator_->Update(camera_center_map, time);
  viewpoint_ = f.viewpoint;
  return f;
}

std::string ViewAnimation::KeyLabel(int key) const { return KeySourceLabel(spec_.keys.at(key)); }

}  // namespace arview::app
