#include "app/pipeline/character_dialogue.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "listen/listen_error.h"

namespace arview::app {

namespace {

constexpr double kDeg = M_PI / 180;

// The enum tables' names are literals: views into them outlive any frame's log.
template <typename E>
std::string_view StableName(E value) {
  for (const auto& entry : EnumNames(E{}))
    if (entry.value == value) return entry.name;
  return {};
}

// The smallest angle (degrees) between `axis` and the directions from `eye` to points along the
// segment [a, b].
double AngleToSegmentDeg(const Eigen::Vector3d& eye, const Eigen::Vector3d& axis, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  constexpr int kSamples = 9;
  double best = 180;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d to = a + (b - a) * (static_cast<double>(i) / (kSamples - 1)) - eye;
    if (to.squaredNorm() < 1e-12) return 0;
    best = std::min(best, std::acos(std::clamp(to.normalized().dot(axis), -1.0, 1.0)) / kDeg);
  }
  return best;
}

}  // namespace

audio::TimePoint FramePacingClock::At(double seconds) {
  return audio::TimePoint{} + std::chrono::duration_cast<audio::Clock::duration>(std::chrono::duration<double>(seconds));
}

audio::TimePoint FramePacingClock::Now() const {
  std::lock_guard lock(mutex_);
  return At(now_s_);
}

bool FramePacingClock::SleepUntil(audio::TimePoint when, const std::stop_token& stop) {
  std::unique_lock lock(mutex_);
  return advanced_.wait(lock, stop, [&] { return At(now_s_) >= when; });
}

void FramePacingClock::Advance(double seconds) {
  {
    std::lock_guard lock(mutex_);
    now_s_ = std::max(now_s_, seconds);
  }
  advanced_.notify_all();
}

CharacterDialogue::CharacterDialogue(dialogue::DialogueManager manager, listen::Recognizer* recognizer,
                                     std::unique_ptr<ReplyVoice> voice, ExpressionTargets expressions,
                                     DialogueOptions options)
    : manager_(std::move(manager)),
      recognizer_(recognizer),
      voice_(std::move(voice)),
      expressions_(std::move(expressions)),
      options_(std::move(options)) {
  if (!voice_) throw Error("dialogue: no voice for the replies");
  grammar_ = manager_.ExpectedPhrases();  // the recognizer was made with them
  frame_.active = true;
}

void CharacterDialogue::Note(std::string problem) {
  if (problems_.size() < 32) problems_.push_back(std::move(problem));
}

dialogue::ViewerInput CharacterDialogue::Viewer(const anim::Placement& placement,
                                                const std::optional<Eigen::Vector3d>& camera_center,
                                                const std::optional<Eigen::Vector3d>& optical_axis) const {
  dialogue::ViewerInput viewer;
  viewer.tracked = camera_center.has_value();
  if (!camera_center) return viewer;
  viewer.distance_m = placement.FloorDistance(*camera_center);
  // Front: the viewpoint (character frame) on the side the character faces, along the floor.
  const Eigen::Vector3d up = options_.up.normalized();
  const Eigen::Vector3d v = placement.ViewpointFromCamera(*camera_center);
  viewer.in_front = (v - v.dot(up) * up).dot(options_.forward - options_.forward.dot(up) * up) >= 0;
  if (optical_axis) {
    const Eigen::Vector3d feet = placement.anchor.position;
    const Eigen::Vector3d head = feet + placement.UpInMap().normalized() * options_.height;
    viewer.gaze_on_character = AngleToSegmentDeg(*camera_center, optical_axis->normalized(), feet, head) <= options_.gaze_cone_deg;
  }
  return viewer;
}

std::optional<std::string> CharacterDialogue::TakeHeard(double time) {
  if (!recognizer_) return std::nullopt;
  std::optional<std::string> heard;
  while (std::optional<listen::Recognition> r = recognizer_->TakeResult()) {
    if (r->kind != listen::HeardKind::kCommand || r->text.empty()) continue;
    heard_ = r->text;
    frame_.heard_confidence = r->confidence;
    frame_.heard_accepted = r->accepted;
    frame_.heard_this_frame = true;
    frame_.heard_now = r->text;
    if (!r->accepted || heard) continue;  // one phrase an update; a second in one frame is rare
    heard = r->text;
    heard_confidence_ = r->confidence;
    heard_end_s_ = options_.sample_time ? options_.sample_time(r->end_sample, time) : -1;
  }
  return heard;
}

void CharacterDialogue::FollowGrammar() {
  if (!recognizer_ || !listening_) return;
  std::vector<std::string> phrases = manager_.ExpectedPhrases();
  if (phrases == grammar_) return;
  grammar_ = std::move(phrases);
  if (grammar_.empty()) return;  // the conversation ended: nothing more to hear
  try {
    recognizer_->Listen(grammar_);  // checked here, compiled by the recognizer's thread
  } catch (const listen::ListenError& e) {
    Note(e.what());
  }
}

void CharacterDialogue::TakeReplies(CharacterSpeech& speech) {
  while (std::optional<ReplyVoice::Made> made = voice_->TakeReady()) {
    if (requested_.empty() || requested_.front().id != made->id) {
      Note("dialogue: a reply came back out of order (id " + std::to_string(made->id) + ")");
      continue;
    }
    const std::size_t turn = requested_.front().turn;
    requested_.pop_front();
    if (!made->line) {
      Note(made->error);
      continue;
    }
    speech.Say(std::move(*made->line));
    handed_to_speech_.push_back(turn);
  }
}

void CharacterDialogue::Update(double time, const anim::Placement& placement, const std::optional<Eigen::Vector3d>& camera_center,
                               const std::optional<Eigen::Vector3d>& optical_axis, CharacterSpeech& speech,
                               anim::Animator& animator) {
  // The replies the speech started since the last frame: their first samples' times.
  const std::vector<double>& started = speech.replies_started();
  for (; replies_started_seen_ < started.size() && !handed_to_speech_.empty(); ++replies_started_seen_) {
    turns_[handed_to_speech_.front()].reply_start_s = started[replies_started_seen_];
    handed_to_speech_.pop_front();
  }
  if (options_.frame_clock) options_.frame_clock->Advance(time);
  const double dt = last_time_ ? std::max(0.0, time - *last_time_) : 0.0;
  last_time_ = time;
  frame_.heard_this_frame = false;
  frame_.heard_now.clear();
  std::optional<std::string> heard = listening_ ? TakeHeard(time) : std::nullopt;
  if (!broken_) {
    dialogue::DialogueInput input;
    input.dt_s = dt;
    input.heard = heard;
    input.viewer = Viewer(placement, camera_center, optical_axis);
    try {
      const dialogue::DialogueTurn turn = manager_.Update(input);
      for (const dialogue::DialogueStep& step : turn.steps) {
        for (const std::string& gesture : step.gestures) {
          if (std::optional<anim::Action> action = voice_->Gesture(gesture, time)) {
            try {
              animator.Play(std::move(*action));
            } catch (const anim::Error&) {  // the schedule full: the gesture is let go (as a line's)
            }
          }
        }
        for (const std::string& said : step.said) {
          DialogueTurnRecord record;
          record.time_s = time;
          record.machine = step.machine;
          record.said = said;
          if (turn.heard_taken && heard) {
            record.heard = *heard;
            record.confidence = heard_confidence_;
            record.heard_end_s = heard_end_s_;
          }
          turns_.push_back(std::move(record));
          const std::uint64_t id = next_id_++;
          if (voice_->Request(id, said, options_.origin + ": machine '" + step.machine + "'")) {
            requested_.push_back({id, turns_.size() - 1});
          } else {
            Note("dialogue: the reply \"" + said + "\" was let go: too many replies waiting to be synthesized");
          }
        }
      }
    } catch (const dialogue::DialogueError& e) {
      Note(e.what());  // the machines went round in circles: the character stops answering
      broken_ = true;
    }
  }
  FollowGrammar();
  TakeReplies(speech);

  // The face follows the dominant emotion, through neutral when the expression changes.
  const dialogue::EmotionSummary mood = manager_.EmotionNow();
  const double step = options_.expression_rate * dt;
  if (expression_ != mood.expression && expression_weight_ > 0) {
    expression_weight_ = std::max(0.0, expression_weight_ - step);
  } else {
    expression_ = mood.expression;
    const double target = mood.expression ? mood.expression_intensity : 0.0;
    expression_weight_ += std::clamp(target - expression_weight_, -step, step);
  }

  frame_.listening = recognizer_ && listening_ && !grammar_.empty();
  frame_.machine = {};
  const std::string selected = manager_.SelectedMachine();
  for (const dialogue::Machine& m : manager_.dialogue().machines)
    if (m.name == selected) frame_.machine = m.name;
  frame_.emotion = mood.dominant ? StableName(*mood.dominant) : std::string_view();
  frame_.emotion_intensity = mood.intensity;
  frame_.expression = expression_ ? StableName(*expression_) : std::string_view();
  frame_.expression_weight = expression_weight_;
  frame_.activation = mood.activation;
  frame_.pause_offset_scale = dialogue::PauseOffsetScale(mood.activation);
  frame_.push_to_talk = options_.push_to_talk && recognizer_;
  frame_.talking = frame_.push_to_talk && talking_;
}

bool CharacterDialogue::TogglePushToTalk() {
  if (!options_.push_to_talk || !recognizer_) return false;
  std::lock_guard lock(talk_mutex_);
  const bool open = !talking_;
  if (open) recognizer_->StartUtterance();
  else recognizer_->StopUtterance();
  talking_ = open;
  return open;
}

void CharacterDialogue::ShowExpression(anim::Animator& animator, const anim::AnimatorFrame& frame) const {
  if (!expression_ || expression_weight_ <= 0) return;
  const auto& targets = expressions_.by_expression[static_cast<std::size_t>(*expression_)];
  for (const auto& [target, weight] : targets) {
    if (target < 0 || static_cast<std::size_t>(target) >= frame.morph_weights.size()) continue;
    float value = weight * static_cast<float>(expression_weight_);
    // Speech owns the mouth while talking: the expression gives it up as speech takes it.
    if (std::find(expressions_.mouth_targets.begin(), expressions_.mouth_targets.end(), target) !=
        expressions_.mouth_targets.end())
      value *= 1.0f - frame.face.talking;
    // A line's own <face> expression, stronger, stays.
    animator.SetMorphWeight(target, std::max(frame.morph_weights[static_cast<std::size_t>(target)], value));
  }
}

}  // namespace arview::app
