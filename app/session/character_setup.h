#pragma once
// A scene character's animation built for the per-frame path: its animator from the scene's
// schedule (anim_authoring/animator_builder.h) with the appliance's overrides, wrapped in the
// pipeline's LayeredAnimator. Shared by the sessions (`run`, `replay`, `demo`) and `arview view`.

#include <memory>
#include <string>

#include "anim_authoring/character_builder.h"
#include "app/pipeline/layered_animator.h"

namespace arview::app {

// `character` must outlive the animator. The default schedule's idle layer is `idle_clip` of the
// asset, or the scene's idle synthesizer, or its look-at base clip ("rest": the rest pose), or
// the asset's first clip, or the rest pose. `fade` overrides the scene's tracking_loss. Throws
// anim::Error for an unknown `idle_clip` or a schedule the character cannot play. A character with
// the 15 viseme targets gets the face speech drives (scene_lines.h, SpeakingFace), and room in its
// schedule for what its lines play; the lines themselves are MakeCharacterSpeech's.
std::unique_ptr<LayeredAnimator> MakeLayeredAnimator(const authoring::AnimatedCharacter& character,
                                                     const std::string& idle_clip = "", const FadeOptions& fade = {});

}  // namespace arview::app
