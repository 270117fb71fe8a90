#pragma once
// The one place `arview view` touches the animation engine: a character of the scene, animated
// from a camera centre and a time exactly as the AR pipeline animates it (the same animator,
// the same viewpoint from the camera centre), and rebuilt when the author changes its keys.
// The asset is loaded once; a key change rebuilds only the key clips.

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

#include "anim_authoring/character_builder.h"
#include "app/pipeline/layered_animator.h"

namespace arview::app {

class ViewAnimation {
 public:
  // Loads the asset and builds the keys; throws anim::Error naming the scene and the problem.
  explicit ViewAnimation(const authoring::CharacterSpec& spec);

  // Rebuilds the key clips for `keys` (throws anim::Error if a key cannot be built, leaving the
  // previous keys in place).
  void SetKeys(const std::vector<authoring::KeySpec>& keys);

  // The animation for a camera centre in map coordinates at `time` seconds. Valid until the
  // next call.
  const anim::AnimatorFrame& Update(const Eigen::Vector3d& camera_center_map, double time);
  // The viewpoint the last Update used (character frame, unit).
  const Eigen::Vector3d& viewpoint() const { return viewpoint_; }

  // What the renderer draws: the asset and the spec (anchor, axes); both stay valid for the
  // lifetime of this object, across SetKeys.
  const anim::Character& asset() const { return *asset_; }
  const authoring::CharacterSpec& spec() const { return spec_; }
  const std::vector<authoring::KeySpec>& keys() const { return spec_.keys; }
  const authoring::AnimatedCharacter& character() const { return *character_; }
  // "Survey", "lookat", "rest", "Walk@0.25": what key k plays.
  std::string KeyLabel(int key) const;
  // What the animation could not do as the scene asked (LayeredAnimator::notes).
  const std::vector<std::string>& notes() const { return animator_->notes(); }
  // The character's rest height in map units.
  double height() const { return height_; }

 private:
  std::shared_ptr<const anim::Character> asset_;
  authoring::CharacterSpec spec_;
  std::unique_ptr<authoring::AnimatedCharacter> character_;
  std::unique_ptr<LayeredAnimator> animator_;
  Eigen::Vector3d viewpoint_ = Eigen::Vector3d::UnitZ();
  double height_ = 1;
};

}  // namespace arview::app
