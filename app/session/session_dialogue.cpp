#include "app/session/session_dialogue.h"

#include <algorithm>
#include <deque>
#include <optional>
#include <set>
#include <utility>

#include "app/session/scene_lines.h"
#include "audio/alsa_capture.h"
#include "audio/wav_source.h"
#include "dialogue/dialogue.h"
#include "figure/face_targets.h"
#include "speech/markup.h"
#include "speech/speech_queue.h"

namespace arview::app {

namespace {

// Replies waiting to be synthesized, at most; a dialogue says one or two per turn.
constexpr std::size_t kRepliesInFlight = 8;

// The markup's gestures the character has clips for (the others were named at load).
void DropUnknownGestures(const authoring::AnimatedCharacter& character, speech::MarkedLine& marked) {
  std::erase_if(marked.tags, [&](const speech::MarkupTag& tag) {
    return tag.kind == speech::TagKind::kGesture && !character.character().FindClip(tag.target);
  });
}

// The dialogue's replies made ready on a SpeechQueue's thread (ReplyVoice): the markup parsed on
// the render thread (microseconds), the sound synthesized off it, the line's actions built when
// its sound comes back.
class ReplyLines final : public ReplyVoice {
 public:
  ReplyLines(const authoring::AnimatedCharacter& character, speech::Voice voice)
      : character_(character), queue_(voice, kRepliesInFlight) {}

  bool Request(std::uint64_t id, const std::string& markup, const std::string& origin) override {
    if (waiting_.size() >= kRepliesInFlight) return false;
    Waiting w{id, {origin, markup}, {}, {}};
    try {
      w.marked = speech::ParseMarkup(markup, origin);
      DropUnknownGestures(character_, w.marked);
      if (!queue_.Submit(id, w.marked.text)) return false;
    } catch (const speech::SpeechError& e) {
      w.error = e.what();
    }
    waiting_.push_back(std::move(w));
    return true;
  }

  std::optional<Made> TakeReady() override {
    if (waiting_.empty()) return std::nullopt;
    Waiting& front = waiting_.front();
    if (front.error.empty()) {
      std::optional<speech::SpeechResult> r = queue_.TakeFinished();  // in submission order
      if (!r) return std::nullopt;
      if (!r->error.empty()) {
        front.error = front.request.origin + ": " + r->error;
      } else {
        try {
          Made made{front.id, MakeReadyLine(character_, front.request, front.marked, std::move(r->line)), {}};
          waiting_.pop_front();
          return made;
        } catch (const Error& e) {
          front.error = e.what();
        }
      }
    }
    Made failed{front.id, std::nullopt, front.error};
    waiting_.pop_front();
    return failed;
  }

  std::optional<anim::Action> Gesture(const std::string& name, double time) override {
    return GestureClipAction(character_, name, time);
  }

 private:
  struct Waiting {
    std::uint64_t id;
    LineRequest request;
    speech::MarkedLine marked;
    std::string error;  // not synthesized: why
  };
  const authoring::AnimatedCharacter& character_;
  speech::SpeechQueue queue_;
  std::deque<Waiting> waiting_;
};

// Every phrase any transition of the dialogue can hear: the recognizer checks their words at load.
std::vector<std::string> EveryPhrase(const dialogue::Dialogue& d) {
  std::vector<std::string> phrases;
  std::set<std::string> seen;
  for (const dialogue::Machine& m : d.machines)
    for (const dialogue::Transition& t : m.transitions)
      for (const dialogue::Condition& c : t.conditions)
        for (const dialogue::Pattern& p : c.patterns)
          if (seen.insert(p.text()).second) phrases.push_back(p.text());
  return phrases;
}

// What the dialogue asks of the character that it cannot do: each gesture it lacks, once.
std::vector<std::string> MissingGestures(const dialogue::Dialogue& d, const authoring::AnimatedCharacter& character) {
  std::set<std::string> missing;
  for (const dialogue::Machine& m : d.machines)
    for (const dialogue::Transition& t : m.transitions)
      for (const dialogue::Action& a : t.actions) {
        if (a.kind == dialogue::Action::Kind::kGesture && !character.character().FindClip(a.text)) missing.insert(a.text);
        if (a.kind != dialogue::Action::Kind::kSay) continue;
        for (const speech::MarkupTag& tag : speech::ParseMarkup(a.text, d.file).tags)
          if (tag.kind == speech::TagKind::kGesture && !character.character().FindClip(tag.target)) missing.insert(tag.target);
      }
  std::vector<std::string> notes;
  for (const std::string& g : missing)
    notes.push_back(d.file + ": the character '" + character.spec().name + "' has no gesture '" + g +
                    "': the dialogue's lines are said without it");
  return notes;
}

// Ekman's six on the character's morph targets, and the mouth's targets speech owns.
ExpressionTargets FaceTargets(const authoring::AnimatedCharacter& character) {
  ExpressionTargets targets;
  const anim::Skeleton& sk = character.character().skeleton;
  for (figure::Expression e : figure::kExpressions)
    for (const figure::TargetWeight& w : figure::ExpressionWeights(e, 1.0))
      if (const int target = sk.FindMorphTarget(w.target); target >= 0)
        targets.by_expression[static_cast<std::size_t>(e)].push_back({target, w.weight});
  if (const std::optional<anim::FaceRig> rig = SpeakingFace(character)) targets.mouth_targets = rig->mouth_targets;
  return targets;
}

}  // namespace

SessionDialogue::SessionDialogue(const DialogueSessionOptions& o, const authoring::AnimatedCharacter& character,
                                 LayeredAnimator& animator, std::function<void(const speech::Utterance&)> on_utterance,
                                 std::function<void(const std::string&)> on_line)
    : on_line_(std::move(on_line)) {
  dialogue::Dialogue d = dialogue::LoadDialogue(o.dialogue_file);
  load_notes_ = MissingGestures(d, character);
  const std::vector<std::string> every_phrase = EveryPhrase(d);
  const std::string file = d.file;
  dialogue::DialogueManager manager(std::move(d), o.seed);
  const bool hears = !o.mic_device.empty() || !o.audio_in.empty();
  if (hears && every_phrase.empty()) load_notes_.push_back(file + ": the dialogue hears nothing (no heard: condition): not listening");
  if (hears && !every_phrase.empty()) {
    listen::RecognizerOptions ro;
    ro.mode = o.push_to_talk ? listen::ListenMode::kPushToTalk : listen::ListenMode::kVoiceActivity;
    ro.decoder.vad_postspeech_frames = o.end_of_speech_frames;
    ro.min_confidence = o.min_confidence;
    recognizer_ = std::make_unique<listen::Recognizer>(ro, every_phrase);  // every word checked now
    if (const std::vector<std::string> now = manager.ExpectedPhrases(); !now.empty()) recognizer_->Listen(now);
  }

  DialogueOptions options;
  options.origin = file;
  options.forward = character.spec().forward;
  options.up = character.spec().up;
  options.push_to_talk = o.push_to_talk;
  if (recognizer_ && !o.audio_in.empty()) {
    frame_clock_ = std::make_unique<FramePacingClock>();
    // Read once: the source hears it, and a video's audio track gets it too (heard_samples).
    heard_samples_ = audio::ReadSpeechWav(o.audio_in, audio::SpeechConversion::kResample);  // another rate, or stereo, converted
    source_ = std::make_unique<audio::WavFileSource>(heard_samples_, *frame_clock_);
    options.frame_clock = frame_clock_.get();
    // Sample 0 is heard at frame time 0 (the source starts before the first frame).
    options.sample_time = [](std::int64_t sample, double) { return static_cast<double>(sample) / audio::kSpeechRate; };
  } else if (recognizer_ && !o.mic_device.empty()) {
    source_ = std::make_unique<audio::AlsaCapture>(audio::CaptureOptions{o.mic_device});
    // The microphone's steady-clock times against the frame clock now: a frame's time trails the
    // steady clock by its latency (tens of ms), which the turns' latency then includes.
    options.sample_time = [this](std::int64_t sample, double frame_time) {
      std::lock_guard lock(mutex_);
      const audio::TimePoint heard =
          block_heard_ + std::chrono::duration_cast<audio::Clock::duration>(
                             std::chrono::duration<double>(static_cast<double>(sample - block_first_) / audio::kSpeechRate));
      return frame_time - std::chrono::duration<double>(audio::Clock::now() - heard).count();
    };
  }

  if (!animator.speech()) {
    SpeechOptions so;
    so.forward = character.spec().forward;
    so.up = character.spec().up;
    so.character = character.spec().name;
    so.on_utterance = std::move(on_utterance);
    animator.SetSpeech(std::make_unique<CharacterSpeech>(std::vector<ReadyLine>{}, std::move(so)));
  }
  auto voice = std::make_unique<ReplyLines>(character, speech::VoiceFromName(character.spec().voice));
  auto owned = std::make_unique<CharacterDialogue>(std::move(manager), recognizer_.get(), std::move(voice),
                                                   FaceTargets(character), std::move(options));
  dialogue_ = owned.get();
  animator.SetDialogue(std::move(owned));
}

SessionDialogue::~SessionDialogue() { Stop(); }

void SessionDialogue::Start() {
  if (!source_ || started_) return;
  started_ = true;
  source_->Start(
      [this](const audio::CapturedBlock& block) {
        {
          std::lock_guard lock(mutex_);
          block_first_ = block.first_sample;
          block_heard_ = block.heard_at;
        }
        recognizer_->Push(block.samples);
      },
      [this](const audio::SourceEnd& end) {
        if (end.error.empty()) return;  // a WAV's end, or the session's stop
        {
          std::lock_guard lock(mutex_);
          audio_error_ = end.error;
        }
        dialogue_->StopListening();
        if (on_line_) on_line_(end.error);  // the session goes on without listening
      });
}

void SessionDialogue::Stop() {
  if (!source_) return;
  source_->RequestStop();
  source_->Join();
}

bool SessionDialogue::TogglePushToTalk() { return dialogue_->TogglePushToTalk(); }

std::string SessionDialogue::audio_error() const {
  std::lock_guard lock(mutex_);
  return audio_error_;
}

}  // namespace arview::app
