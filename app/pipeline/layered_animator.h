#pragma once
// The character's animation as the appliance drives it (docs/method.md §2), on anim/'s MIRAnim
// engine (anim/animator.h): a schedule per character — by default the idle layer underneath
// (the scene's idle synthesizer, or the base clip looped, or the rest pose) and the
// view-adaptive action on top, or the scene's own `schedule:`. While the tracker follows the
// camera the view-adaptive action has full weight. When tracking is lost the character holds its
// last viewpoint for `hold_seconds` (time keeps running: no freeze), then the view-adaptive
// action fades out (cosine, over `fade_seconds`) to the layers below it; when the tracker
// relocalizes it fades back. The fade blends local joint transforms (dual quaternions), so bones
// keep their lengths and no joint jumps. The viewer's distance to the character (map units,
// along the character's floor: the camera's height above it does not count) drives the scene's
// distance triggers and weights.
//
// The animator is built from the scene by the session (app/session/character_setup.h); this is
// the per-frame half.

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "anim/placed_character.h"
#include "app/pipeline/character_dialogue.h"
#include "app/pipeline/character_speech.h"
#include "base/option_check.h"

namespace arview::app {

struct FadeOptions {
  double hold_seconds = 0.5;
  double fade_seconds = 1.0;

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

class LayeredAnimator {
 public:
  // `character` must outlive the animator; `animator` plays its schedule. `idle_clip` is the clip
  // of the default idle layer (nullptr: rest pose, idle synthesizer or the scene's schedule);
  // `notes` what the user should be told about the animation built.
  LayeredAnimator(const anim::PlacedCharacter& character, std::unique_ptr<anim::Animator> animator,
                  const anim::Clip* idle_clip = nullptr, std::vector<std::string> notes = {});

  // `camera_center` is the (smoothed) camera centre in map coordinates, or nothing when the
  // tracker lost the frame. `time` is the video time in seconds (monotonic). `optical_axis`: the
  // camera's viewing direction in the map (for the dialogue's gaze condition), when known.
  const anim::AnimatorFrame& Update(const std::optional<Eigen::Vector3d>& camera_center, double time,
                                    const std::optional<Eigen::Vector3d>& optical_axis = std::nullopt);

  // The character's lines (app/pipeline/character_speech.h), set before the pipeline starts:
  // each Update then lets them start a line and drive the face.
  void SetSpeech(std::unique_ptr<CharacterSpeech> speech) { speech_ = std::move(speech); }
  const CharacterSpeech* speech() const { return speech_.get(); }
  // The character's dialogue (issue 54), set before the pipeline starts, after SetSpeech (its
  // replies are said by the speech): each Update ticks it first and shows its expression after.
  void SetDialogue(std::unique_ptr<CharacterDialogue> dialogue);
  const CharacterDialogue* dialogue() const { return dialogue_.get(); }
  // The line being said, empty when silent or without lines.
  std::string_view saying() const { return speech_ ? speech_->saying() : std::string_view(); }

  // The clip of the default idle layer, or nullptr (rest pose, idle synthesizer, scene schedule).
  const anim::Clip* idle_clip() const { return idle_; }
  const anim::PlacedCharacter& character() const { return character_; }
  anim::Animator& animator() { return *animator_; }
  // What the user should be told about the animation built (one line each, for "note: "): a
  // layer the scene asked for that its data cannot support, e.g. balance shifts from a recording
  // without a transition.
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  const anim::PlacedCharacter& character_;
  const anim::Clip* idle_ = nullptr;
  std::unique_ptr<anim::Animator> animator_;
  std::vector<std::string> notes_;
  std::unique_ptr<CharacterSpeech> speech_;
  std::unique_ptr<CharacterDialogue> dialogue_;
};

}  // namespace arview::app
