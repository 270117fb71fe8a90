#pragma once
// A scene's character built (the authoring half of anim::PlacedCharacter): the asset loaded, its
// keys built (clips from the asset, generated look-at and gesture keys, static poses), the
// view-adaptive blend over them. What the per-frame path needs is the PlacedCharacter it is;
// spec() keeps the scene's description for the tools that edit it (`arview view`).
//
//   AnimatedCharacter fox(scene.characters[0]);           // throws Error naming the scene line
//   const anim::PlacedCharacter& placed = fox;             // → the pipeline, the renderer
//   const AnimatorFrame& f = fox.Update(v, time_seconds);  // the blend alone, no allocation

#include <memory>
#include <string>

#include "anim/placed_character.h"
#include "anim_authoring/scene.h"

namespace arview::authoring {

class AnimatedCharacter : public anim::PlacedCharacter {
 public:
  // Loads spec.asset and prepares one clip per key (from the asset, generated, or static).
  // Throws Error naming the scene/asset and the problem (e.g. a clip that does not exist).
  explicit AnimatedCharacter(const CharacterSpec& spec);
  AnimatedCharacter(std::shared_ptr<const anim::Character> character, const CharacterSpec& spec);

  const CharacterSpec& spec() const { return spec_; }

 private:
  CharacterSpec spec_;
};

// The clip names of `character`, for messages: "Survey, Walk, Run", or "none".
std::string ClipList(const anim::Character& character);

}  // namespace arview::authoring
