#pragma once
// A scene character's animator (anim/animator.h) built from its `schedule:` or the default one,
// and its idle layer learned from the scene's `idle:` data.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "anim/blendable.h"
#include "anim/idle.h"
#include "anim_authoring/character_builder.h"

namespace arview::authoring {

// What the appliance may override in the scene's schedule.
struct AnimatorOverrides {
  std::string idle_clip;                  // the default schedule's idle layer: this clip (looped)
  std::optional<double> hold_seconds, fade_seconds;  // tracking loss
  // The face speech drives (anim/face.h), built by the layer that knows the character's jaw
  // shares (app/session for the built-in figure); nothing: the character does not speak.
  std::optional<anim::FaceRig> face;
  // Room in the schedule for actions played while the character runs (a line's gestures and
  // expressions, anim::Animator::Play), beyond what the scene's own actions take.
  int played_actions = 0;
};

// The character's animator (anim/animator.h): its scene `schedule:` built (objects, modifiers,
// curves, masks with scopes resolved on its skeleton, distance triggers and weights), or by
// default the idle underneath (the `idle:` synthesizer if given, else the look-at base clip
// looped, else the first clip, else the rest pose) and the view-adaptive action "view" on top.
// `character` must outlive the animator. Throws Error "scene:line: why". `notes` (if given)
// receive what the appliance should tell its user: a layer the scene asked for that the data
// cannot support (see BuildIdleLayer).
std::unique_ptr<anim::Animator> BuildAnimator(const AnimatedCharacter& character, const AnimatorOverrides& overrides = {},
                                        std::vector<std::string>* notes = nullptr);

// The idle synthesizer of the character's `idle:` section (learned here), with what was learned.
std::shared_ptr<anim::IdleSynthesizer> BuildIdle(const AnimatedCharacter& character, std::string* summary = nullptr);

// What BuildIdleLayer learned: the idle synthesizer's summary, the balance learner's (empty
// without `idle.balance:`), and notes for the user: "scene:line: idle.balance: <recording>: what
// it holds; 0 transitions: ..." when the balance layer was asked for and not built.
struct IdleLayerReport {
  std::string idle, balance;
  bool balance_built = false;  // the balance-shift layer runs under the synthesizer's variations
  std::vector<std::string> notes;
};

// The character's idle layer (`idle: true` objects and the default schedule's idle action): the
// idle synthesizer, under which, when the scene enables `idle.balance:` and its recording holds
// balance shifts, the balance-shift layer runs (anim/balance_shift.h: the synthesizer's
// variations on top of the shifts). A recording without a transition gives the synthesizer alone
// and a note: nothing is invented. Throws Error "scene:line: idle...: why" for bad data.
anim::BlendablePtr BuildIdleLayer(const AnimatedCharacter& character, IdleLayerReport* report = nullptr);

}  // namespace arview::authoring
