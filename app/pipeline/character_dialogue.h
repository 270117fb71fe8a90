#pragma once
// The character listens and answers on the frame path (issue 54): every frame, on arview-render,
// CharacterDialogue takes what the recognizer heard (never waiting: listen::Recognizer decodes on
// its own thread), ticks the dialogue manager with the frame time (the emotions decay over it)
// and the viewer as the tracker sees them, hands each reply's `say` to a ReplyVoice that
// synthesizes it on a thread of its own, and gives a reply that has come back to the character's
// speech (CharacterSpeech::Say: the path scene lines take). The grammar follows what the dialogue
// can hear next. The dominant emotion drives the face's expression (its morph targets' weights,
// written after the animator's update) and is shown on the HUD.
//
// Threads: arview-render alone calls Update and reads what the accessors return; the recognizer
// and the reply voice are fed and polled from there and never waited on. The audio that feeds
// the recognizer comes from another thread (the microphone's, or a WAV paced by FramePacingClock).

#include <Eigen/Core>

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "anim/animator.h"
#include "anim/placement.h"
#include "app/pipeline/character_speech.h"
#include "audio/pacing_clock.h"
#include "dialogue/dialogue.h"
#include "listen/recognizer.h"

namespace arview::app {

// Makes the dialogue's replies ready to say, off the frame path (the session's implementation
// parses the markup, synthesizes on a SpeechQueue's thread and builds the line's actions for the
// character). Both calls are the render thread's and never wait.
class ReplyVoice {
 public:
  virtual ~ReplyVoice() = default;
  // Queues a reply's markup (the dialogue's `say`, filled in); false when it cannot be queued.
  virtual bool Request(std::uint64_t id, const std::string& markup, const std::string& origin) = 0;
  // A reply made ready since the last call (in the order requested), or nothing yet. A reply that
  // could not be made comes back with no line and its one-line reason.
  struct Made {
    std::uint64_t id = 0;
    std::optional<ReadyLine> line;
    std::string error;
  };
  virtual std::optional<Made> TakeReady() = 0;
  // The dialogue's `gesture: NAME` (no words) as an action starting at schedule time `time`, or
  // nothing when the character has no such clip (said once at load by the session).
  virtual std::optional<anim::Action> Gesture(const std::string& name, double time) = 0;
};

// A WAV replayed as a microphone paced by the session's frame clock ("the application's clock"):
// the render thread advances it to each frame's animation time, and WavFileSource delivers the
// samples up to it. TimePoint{} + t seconds is frame time t.
class FramePacingClock final : public audio::PacingClock {
 public:
  audio::TimePoint Now() const override;
  bool SleepUntil(audio::TimePoint when, const std::stop_token& stop) override;
  // The render thread: the frame time reached (seconds, monotonic).
  void Advance(double seconds);
  static audio::TimePoint At(double seconds);

 private:
  mutable std::mutex mutex_;
  std::condition_variable_any advanced_;
  double now_s_ = 0;
};

// One turn as --stats records it: what was heard and the reply it brought.
struct DialogueTurnRecord {
  double time_s = 0;         // frame time at which the dialogue took it
  std::string heard;         // what was heard ("" for a turn the viewer's movement made)
  double confidence = 0;     // the recognizer's (0 without words)
  double heard_end_s = -1;   // the end of the viewer's words on the frame clock (< 0: nothing heard)
  std::string machine;       // the machine that answered
  std::string said;          // the reply's markup
  double reply_start_s = -1;  // when its first sample is due on the frame clock (< 0: not said)
  // From the end of the viewer's words to the reply's first sample (< 0: not both).
  double LatencyS() const { return heard_end_s >= 0 && reply_start_s >= 0 ? reply_start_s - heard_end_s : -1; }
};

// What the frame's log and the HUD show of the dialogue.
// Views are into the dialogue file's names and the enums' tables: they outlive the frame's log.
struct DialogueFrame {
  bool active = false;
  std::string heard_now;        // what was heard, on the frame a result came (else empty)
  double heard_confidence = 0;  // the last result's
  bool heard_accepted = false;
  bool heard_this_frame = false;
  std::string_view machine;     // the machine chosen last ("" before any)
  std::string_view emotion;     // the dominant emotion ("" while all are 0)
  double emotion_intensity = 0;
  std::string_view expression;  // the face's expression for it ("" when neutral)
  double expression_weight = 0;  // its weight on the face (0..1)
  double activation = 0;
  bool listening = false;       // a recognizer is being fed
  bool push_to_talk = false;    // the recognizer hears only while the key has opened it
  bool talking = false;         // push-to-talk: the key has opened listening
  // The idle's pause offset scale from the activation (dialogue::PauseOffsetScale, thesis Eq. 4.2):
  // handed to the animator as anim::FrameInputs::pause_offset_scale.
  double pause_offset_scale = 1;
};

// The window's key that opens and closes listening in push-to-talk mode (an X keysym name). A
// toggle, not a held key: the window reports key presses only, and X's auto-repeat sends
// release-press pairs while a key is held, so a held key could not be told from fast presses.
inline constexpr std::string_view kPushToTalkKey = "space";

// The morph targets of each of Ekman's six expressions at full intensity (dialogue::Expression's
// order), found on the character at load; and the mouth targets that speech owns while talking.
struct ExpressionTargets {
  std::array<std::vector<std::pair<int, float>>, 6> by_expression;
  std::vector<int> mouth_targets;
};

struct DialogueOptions {
  std::string origin;            // the dialogue file, for the replies' origins
  // The character's front and up in its frame (the viewer's side), as SpeechOptions's.
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ(), up = Eigen::Vector3d::UnitY();
  // The viewer looks at the character when the camera's axis passes within this angle of the
  // segment from its feet to `height` above them (map units).
  double gaze_cone_deg = 15;
  double height = 1.7;
  // The expression's weight follows the dominant emotion's intensity at this rate (per second),
  // so that the face does not jump when the dominant emotion changes.
  double expression_rate = 2.0;
  // Sample clock → frame clock: the frame time at which input sample `sample` was heard, given
  // the frame time now (a WAV on FramePacingClock: sample / 16000; a microphone: by its blocks'
  // times). Null: the turns' latency is not known.
  std::function<double(std::int64_t sample, double frame_time)> sample_time;
  // A WAV's pacing clock, advanced to each frame's time at the start of Update (null: none).
  FramePacingClock* frame_clock = nullptr;
  // The recognizer is in push-to-talk mode (listen::ListenMode::kPushToTalk): it hears what comes
  // between two TogglePushToTalk calls (kPushToTalkKey in the window).
  bool push_to_talk = false;
};

class CharacterDialogue {
 public:
  // `recognizer` may be null (nothing heard: the viewer's movements still drive the dialogue).
  // `voice` makes the replies; `expressions` may be empty (no face).
  CharacterDialogue(dialogue::DialogueManager manager, listen::Recognizer* recognizer, std::unique_ptr<ReplyVoice> voice,
                    ExpressionTargets expressions, DialogueOptions options);

  // Per frame, before the character's speech and animator updates. `camera_center` (map) and
  // `optical_axis` (map, unit) are nothing when the frame was lost.
  // Gestures without words are played on `animator`.
  void Update(double time, const anim::Placement& placement, const std::optional<Eigen::Vector3d>& camera_center,
              const std::optional<Eigen::Vector3d>& optical_axis, CharacterSpeech& speech, anim::Animator& animator);
  // After the animator's update: the emotion's expression on the face's targets (given up on the
  // mouth as speech takes it).
  void ShowExpression(anim::Animator& animator, const anim::AnimatorFrame& frame) const;

  const DialogueFrame& frame() const { return frame_; }
  // The last thing heard (accepted or not), for the HUD.
  const std::string& last_heard() const { return heard_; }
  // Every turn so far, in order (a reply's start filled in once it is said).
  const std::vector<DialogueTurnRecord>& turns() const { return turns_; }
  const dialogue::DialogueManager& manager() const { return manager_; }
  // One line per problem met while running (a reply that could not be made, a grammar the
  // recognizer refused), for the session's end; never thrown on the frame path.
  const std::vector<std::string>& problems() const { return problems_; }
  // The recognizer's input is gone (a microphone unplugged): the session goes on without
  // listening, and the HUD says so. Any thread (the audio source's).
  void StopListening() { listening_ = false; }
  // Push-to-talk (DialogueOptions::push_to_talk): the key opens listening, the next press closes
  // it and the utterance between is decoded. Any thread (the window's key handler on arview-sink):
  // the recognizer's StartUtterance/StopUtterance take effect at its input's position when called.
  // Returns whether listening is now open; false, and nothing done, without push-to-talk.
  bool TogglePushToTalk();

 private:
  dialogue::ViewerInput Viewer(const anim::Placement& placement, const std::optional<Eigen::Vector3d>& camera_center,
                               const std::optional<Eigen::Vector3d>& optical_axis) const;
  std::optional<std::string> TakeHeard(double time);
  void FollowGrammar();
  void TakeReplies(CharacterSpeech& speech);
  void Note(std::string problem);

  dialogue::DialogueManager manager_;
  listen::Recognizer* recognizer_;
  std::unique_ptr<ReplyVoice> voice_;
  ExpressionTargets expressions_;
  DialogueOptions options_;
  std::atomic<bool> listening_{true};
  std::mutex talk_mutex_;                  // one toggle at a time: the recognizer sees start, stop, start, ...
  std::atomic<bool> talking_{false};       // push-to-talk: the key has opened listening
  bool broken_ = false;                    // a DialogueError at run time: no more turns
  double heard_confidence_ = 0, heard_end_s_ = -1;  // of the phrase taken this frame
  std::optional<double> last_time_;
  std::vector<std::string> grammar_;       // the phrases the recognizer listens for
  std::string heard_;                      // the last thing heard, for the HUD
  struct Pending {                         // a reply requested, not yet said
    std::uint64_t id;
    std::size_t turn;
  };
  std::deque<Pending> requested_;          // in order
  std::deque<std::size_t> handed_to_speech_;  // turns whose lines CharacterSpeech has queued
  std::size_t replies_started_seen_ = 0;
  std::uint64_t next_id_ = 0;
  std::vector<DialogueTurnRecord> turns_;
  std::vector<std::string> problems_;
  double expression_weight_ = 0;
  std::optional<dialogue::Expression> expression_;
  DialogueFrame frame_;
};

}  // namespace arview::app
