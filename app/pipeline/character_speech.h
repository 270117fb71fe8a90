#pragma once
// A character's lines on the frame path (issue 53): the lines come ready (synthesized ahead on
// the SpeechQueue's thread at load, app/session/scene_lines.h); every frame, on arview-render,
// CharacterSpeech watches the cues (the first tracked frame, the viewer coming close, walking
// behind the character, tracking lost and found), starts a line when its cue comes and no line
// is being said, hands the line's gestures, expression and gaze to the animator at their words'
// times, and samples the line's viseme curves into the frame's anim::FaceTrack. Nothing here
// synthesizes, and nothing allocates per frame but a line's start (its actions, its utterance).
//
// Threads: arview-render alone calls Update; the utterance callback runs there.

#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "anim/animator.h"
#include "speech/line_cue.h"
#include "speech/utterance.h"
#include "speech/visemes.h"

namespace arview::app {

using SpeechCue = speech::LineCue;

// A line ready to say: its sound and timing, its viseme curves, its markup's actions.
struct ReadyLine {
  std::string origin;  // "scene.yaml:14"
  std::string text;    // what is spoken (the markup's tags taken out)
  SpeechCue cue = SpeechCue::kStart;
  double near = 1.5, far = 2.0;  // kNear: fires within `near`, re-arms beyond `far` (map units)
  std::shared_ptr<const speech::SpokenLine> spoken;
  std::shared_ptr<const speech::VisemeTrack> visemes;
  // The <gesture> and <face> tags as schedule actions, each `start` relative to the line's start.
  std::vector<anim::Action> actions;
  std::vector<double> gaze_at_viewer;  // <gaze at="viewer"/>: from these times (line-relative) to the line's end
  double duration_s() const { return spoken ? spoken->DurationSeconds() : 0; }
};

// What the frame tells the speech layer.
struct SpeechCues {
  bool tracking = false;
  double distance = -1;  // along the floor, map units; < 0 unknown
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // the character's frame (Placement)
};

struct SpeechOptions {
  // The character's front and up in its frame: "behind" is the viewer more than
  // `behind_deg` from the front (re-armed within `front_deg`), along the floor.
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ(), up = Eigen::Vector3d::UnitY();
  double behind_deg = 120, front_deg = 90;
  double lost_after_s = 0.5;      // a loss says its line once it has lasted this long (not a one-frame blip)
  double ramp_s = 0.08;           // speech takes the mouth over and gives it back over this
  std::string character;          // for the utterances
  // A cued line starts this long after its cue (0: on the cue's frame), rounded up to whole frame
  // intervals (the last one seen), so that it starts on a frame: a live session's sound must reach
  // the player its lead ahead of the frame it plays with (app/session/session_sound.h).
  double start_delay_s = 0;
  // Called on arview-render when a line starts (the audio's sinks take it from there; must not block).
  std::function<void(const speech::Utterance&)> on_utterance;
};

class CharacterSpeech {
 public:
  CharacterSpeech(std::vector<ReadyLine> lines, SpeechOptions options);

  // Per frame, before the animator's Update: the cues may start a line (its actions are played on
  // `animator`); returns the frame's face track. `time`: the animation time (seconds, monotonic).
  const anim::FaceTrack& Update(double time, const SpeechCues& cues, anim::Animator& animator);

  // A line said as soon as no line is being said, before any cued line: the dialogue's replies
  // (app/pipeline/character_dialogue.h). Lines given here wait in order.
  void Say(ReadyLine line);
  // The frame times at which Say's lines started, in the order given.
  const std::vector<double>& replies_started() const { return replies_started_; }

  // The line being said (its text), empty when silent.
  std::string_view saying() const;
  // Every line started so far, in order.
  const std::vector<speech::Utterance>& utterances() const { return utterances_; }
  // A deque: Say appends while the sink's thread may still read an earlier line's text (saying()).
  const std::deque<ReadyLine>& lines() const { return lines_; }

 private:
  // Advances the cues' states; the line a cue calls for this frame, or −1.
  int Cued(double time, const SpeechCues& cues);
  int NextLineFor(SpeechCue cue);  // the cue's lines take turns; −1: it has none
  void Start(std::size_t line, double time, anim::Animator& animator);
  double DelayedStart(double cue_time) const;  // SpeechOptions::start_delay_s on whole frames

  std::deque<ReadyLine> lines_;  // the scene's lines first (scene_lines_ of them), then Say's
  std::size_t scene_lines_ = 0;
  SpeechOptions options_;
  std::vector<std::size_t> next_by_cue_;  // per cue: where to look for its next line
  std::vector<bool> near_armed_;          // per line (kNear lines: their own distances)
  bool started_ = false;                  // the first tracked frame has come (kStart)
  bool behind_armed_ = true;
  bool has_lost_since_ = false, lost_said_ = false;  // a loss under way; its kLost fired (kFound follows)
  double lost_since_ = 0;
  int current_ = -1;  // the line being said
  double current_start_ = 0;
  double last_time_ = -1, frame_interval_ = 0;  // the previous frame's time and the interval to it
  anim::FaceTrack track_;
  std::vector<speech::Utterance> utterances_;
  std::deque<std::size_t> replies_waiting_;  // Say's lines not yet started
  std::vector<double> replies_started_;
};

}  // namespace arview::app
