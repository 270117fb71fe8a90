#include "app/pipeline/character_speech.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace arview::app {

namespace {

constexpr double kDeg = M_PI / 180;

// anim's viseme slots are speech's visemes, in the same order.
static_assert(anim::kVisemeSlots == speech::kVisemeCount);
bool SlotsMatchSpeech() {
  for (std::size_t v = 0; v < speech::kVisemeCount; ++v) {
    const std::string name = "viseme_" + std::string(ToString(static_cast<speech::Viseme>(v)));
    if (name != anim::VisemeTargetNames()[v]) return false;
  }
  return true;
}

// The viewer's angle from the character's front, along the floor (degrees, 0..180).
double AngleFromFront(const Eigen::Vector3d& viewpoint, const SpeechOptions& o) {
  const Eigen::Vector3d up = o.up.normalized();
  const Eigen::Vector3d v = viewpoint - viewpoint.dot(up) * up;
  const Eigen::Vector3d f = o.forward - o.forward.dot(up) * up;
  if (v.squaredNorm() < 1e-12 || f.squaredNorm() < 1e-12) return 0;  // straight above: not behind
  return std::acos(std::clamp(v.normalized().dot(f.normalized()), -1.0, 1.0)) / kDeg;
}

}  // namespace

CharacterSpeech::CharacterSpeech(std::vector<ReadyLine> lines, SpeechOptions options)
    : lines_(std::make_move_iterator(lines.begin()), std::make_move_iterator(lines.end())),
      scene_lines_(lines_.size()),
      options_(std::move(options)),
      next_by_cue_(5, 0),
      near_armed_(lines_.size(), true) {
  if (!SlotsMatchSpeech()) throw Error("speech: anim's viseme slots are not speech's visemes (anim/face.cpp, speech/visemes.h)");
  for (const ReadyLine& l : lines_)
    if (!l.spoken || !l.visemes) throw Error(l.origin + ": the line was not synthesized");
  utterances_.reserve(64);
}

void CharacterSpeech::Say(ReadyLine line) {
  if (!line.spoken || !line.visemes) throw Error(line.origin + ": the line was not synthesized");
  lines_.push_back(std::move(line));
  replies_waiting_.push_back(lines_.size() - 1);
}

std::string_view CharacterSpeech::saying() const {
  return current_ >= 0 ? std::string_view(lines_[current_].text) : std::string_view();
}

int CharacterSpeech::NextLineFor(SpeechCue cue) {
  const std::size_t c = static_cast<std::size_t>(cue);
  for (std::size_t k = 0; k < scene_lines_; ++k) {
    const std::size_t i = (next_by_cue_[c] + k) % scene_lines_;
    if (lines_[i].cue == cue) {
      next_by_cue_[c] = i + 1;  // the cue's lines take turns
      return static_cast<int>(i);
    }
  }
  return -1;
}

int CharacterSpeech::Cued(double time, const SpeechCues& cues) {
  int due = -1;
  auto fire = [&](SpeechCue cue) {
    if (due < 0) due = NextLineFor(cue);
  };
  if (cues.tracking) {
    if (!started_) {
      started_ = true;
      fire(SpeechCue::kStart);
    }
    if (lost_said_) fire(SpeechCue::kFound);
    lost_said_ = false;
    has_lost_since_ = false;
    for (std::size_t i = 0; i < scene_lines_; ++i) {
      const ReadyLine& l = lines_[i];
      if (l.cue != SpeechCue::kNear || !(cues.distance >= 0)) continue;
      if (near_armed_[i] && cues.distance <= l.near) {
        near_armed_[i] = false;
        if (due < 0) due = static_cast<int>(i);
      } else if (!near_armed_[i] && cues.distance > l.far) {
        near_armed_[i] = true;
      }
    }
    const double angle = AngleFromFront(cues.viewpoint, options_);
    if (behind_armed_ && angle > options_.behind_deg) {
      behind_armed_ = false;
      fire(SpeechCue::kBehind);
    } else if (!behind_armed_ && angle < options_.front_deg) {
      behind_armed_ = true;
    }
  } else if (started_) {
    if (!has_lost_since_) {
      has_lost_since_ = true;
      lost_since_ = time;
    }
    if (!lost_said_ && time - lost_since_ >= options_.lost_after_s) {
      lost_said_ = true;  // `found` follows when the tracker finds the viewer again
      fire(SpeechCue::kLost);
    }
  }
  return due;
}

// `time`: the line's start, its cue's frame or a later one (DelayedStart).
void CharacterSpeech::Start(std::size_t index, double time, anim::Animator& animator) {
  const ReadyLine& line = lines_[index];
  current_ = static_cast<int>(index);
  current_start_ = time;
  for (const anim::Action& a : line.actions) {
    anim::Action action = a;
    action.start += time;
    // The schedule has room for several lines' actions at once (PlayedActionRoom); lines said back
    // to back whose gestures outlast them could still fill it (Add's one refusal for an action
    // built for this skeleton at load): the gesture is let go, the line is said.
    try {
      animator.Play(std::move(action));
    } catch (const anim::Error&) {
    }
  }
  for (double g : line.gaze_at_viewer) animator.HoldGazeOnViewer(time + g, time + line.duration_s());
  speech::Utterance u;
  u.sequence = utterances_.size();
  u.start_s = time;
  u.line = line.spoken;
  u.character = options_.character;
  u.origin = line.origin;
  utterances_.push_back(u);
  if (options_.on_utterance) options_.on_utterance(utterances_.back());
}

double CharacterSpeech::DelayedStart(double time) const {
  if (options_.start_delay_s <= 0) return time;
  if (frame_interval_ <= 0) return time + options_.start_delay_s;
  return time + std::ceil(options_.start_delay_s / frame_interval_ - 1e-9) * frame_interval_;
}

const anim::FaceTrack& CharacterSpeech::Update(double time, const SpeechCues& cues, anim::Animator& animator) {
  if (last_time_ >= 0 && time > last_time_) frame_interval_ = time - last_time_;
  last_time_ = time;
  const int due = Cued(time, cues);
  if (current_ >= 0 && time - current_start_ > lines_[current_].duration_s() + options_.ramp_s) current_ = -1;
  if (current_ < 0 && !replies_waiting_.empty()) {
    const double start = DelayedStart(time);
    Start(replies_waiting_.front(), start, animator);  // a reply before a cue, which is let go
    replies_waiting_.pop_front();
    replies_started_.push_back(start);
  } else if (current_ < 0 && due >= 0) {
    Start(static_cast<std::size_t>(due), DelayedStart(time), animator);  // a cue while talking is let go
  }
  track_ = anim::FaceTrack{};
  if (current_ < 0) return track_;
  const ReadyLine& line = lines_[current_];
  const double local = time - current_start_;
  if (local < 0) return track_;  // a delayed line: the mouth waits for its start
  const double ramp = std::max(options_.ramp_s, 1e-3);
  track_.talking = static_cast<float>(std::clamp(std::min(local / ramp, (line.duration_s() + ramp - local) / ramp), 0.0, 1.0));
  speech::VisemeWeights weights;
  line.visemes->Sample(local, weights);
  std::copy(weights.begin(), weights.end(), track_.visemes.begin());
  return track_;
}

}  // namespace arview::app
