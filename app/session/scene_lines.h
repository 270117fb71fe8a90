#pragma once
// A character's lines made ready to say (issue 53, docs/speech.md "Lines in scenes"), at load:
// each line's markup parsed (speech/markup.h); its gestures, expressions and gaze checked against
// the character; its text synthesized on a SpeechQueue's thread, all lines at once, before the
// first frame (never on the frame path); its tags timed at their words and turned into schedule
// actions. Also the built-in figure's face rig (its jaw shares), which anim_authoring cannot see.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "anim/face.h"
#include "anim_authoring/character_builder.h"
#include "app/pipeline/character_speech.h"
#include "speech/markup.h"
#include "speech/utterance.h"

namespace arview::app {

// One line to prepare: its markup and where it was written ("scene.yaml:14"), its cue.
struct LineRequest {
  std::string origin;
  std::string markup;
  SpeechCue cue = SpeechCue::kStart;
  double near = 1.5, far = 2.0;
};

// Timing of what a line's tags start (seconds).
struct LineActionTiming {
  double gesture_fade_in = 0.2, gesture_fade_out = 0.4;
  double face_fade_in = 0.3, face_fade_out = 0.6;
  double face_hold_after_line = 1.0;  // the expression stays this long after the line ends
  int gesture_layer = 8;              // over the idle and the view-adaptive layers
  double gesture_min_turn_deg = 5.0;  // a gesture's upper-body joints that turn less stay below
  int face_layer = 9;
};

// The lines of `character` (the scene's `lines:` unless `requests` is given), ready to say with
// `voice_name` (Flite's: slt, rms, awb). Throws speech::SpeechError or anim::Error, one line naming
// the scene's line: bad markup, text over the limit, a voice that does not exist, a gesture the
// character has no clip for, an expression it cannot show, a gaze at anything but the viewer.
std::vector<ReadyLine> PrepareLines(const authoring::AnimatedCharacter& character, const std::vector<LineRequest>& requests,
                                    const std::string& voice_name, const std::string& voice_origin,
                                    const LineActionTiming& timing = {});
// One line made ready from its parsed markup and its synthesized sound (what PrepareLines does for
// each line; the dialogue's replies are made one at a time): its viseme track, its tags timed at
// their words as schedule actions. Throws anim::Error for a gesture or expression the character
// cannot play.
ReadyLine MakeReadyLine(const authoring::AnimatedCharacter& character, const LineRequest& request,
                        const speech::MarkedLine& marked, speech::SpokenLine spoken, const LineActionTiming& timing = {});
// The character's clip `name` as a gesture starting at `start`: over the idle and the view layer
// on the upper-body joints the clip moves (the legs, and the head the look-at turns to the viewer
// when the clip leaves it still, stay on the layers below), faded in and out. Nothing when the
// character has no such clip.
std::optional<anim::Action> GestureClipAction(const authoring::AnimatedCharacter& character, const std::string& name,
                                              double start, const LineActionTiming& timing = {});
// The scene's `lines:` of the character as requests.
std::vector<LineRequest> SceneLineRequests(const authoring::CharacterSpec& spec);

// The face rig speech drives on `character`: its viseme and mouth targets by name, and for the
// built-in figure its visemes' jaw shares and jawOpen's angle (figure/face_targets.h), so that the
// Jaw joint opens the mouth. Nothing for a character without the 15 viseme targets.
std::optional<anim::FaceRig> SpeakingFace(const authoring::AnimatedCharacter& character);

// The schedule room a character's lines need for what they play (anim::Animator::Play).
int PlayedActionRoom(const authoring::CharacterSpec& spec);

// The character's CharacterSpeech from its scene lines, or nullptr when it has none. Its lines
// start `start_delay_s` after their cues (SpeechOptions::start_delay_s).
std::unique_ptr<CharacterSpeech> MakeCharacterSpeech(const authoring::AnimatedCharacter& character,
                                                     std::function<void(const speech::Utterance&)> on_utterance,
                                                     double start_delay_s = 0);

}  // namespace arview::app
