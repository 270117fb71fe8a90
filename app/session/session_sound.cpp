#include "app/session/session_sound.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arview::app {

namespace {

constexpr std::size_t kOffsetFrames = 31;
// A frame "reaches" a line's start within a microsecond (the frame clock's timestamps are doubles).
constexpr double kSameTime = 1e-6;

std::int64_t Nanoseconds(Clock::duration d) { return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count(); }

std::int64_t MedianOf(std::vector<std::int64_t> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

SessionSound::SessionSound(audio::ClipPlayer* player, video::FrameSink& sink, double fps)
    : player_(player), sink_(sink), fps_(fps) {
  offsets_ns_.reserve(kOffsetFrames);
}

void SessionSound::OnUtterance(const speech::Utterance& utterance) {
  if (!active() || !utterance.line) return;
  const std::lock_guard lock(mutex_);
  Pending line;
  line.sound.id = next_id_++;
  line.sound.start_s = utterance.start_s;
  line.sound.origin = utterance.origin;
  line.utterance = utterance;
  line.to_player = player_ != nullptr;
  line.to_video = sink_.HasAudio();
  incoming_.push_back(std::move(line));
}

void SessionSound::AddHeardAudio(const std::vector<std::int16_t>& samples) {
  if (sink_.HasAudio()) heard_ = samples;
}

double SessionSound::SinceStart(Clock::time_point t) const {
  return pipeline_start_ ? std::chrono::duration<double>(t - *pipeline_start_).count() : -1;
}

void SessionSound::OnFrameShown(const FrameLog& frame, Clock::time_point shown) {
  if (!active()) return;
  if (!pipeline_start_) {
    // The frames' clock in stats.json: captured_s + latency_ms is when the frame was shown.
    pipeline_start_ = shown - std::chrono::duration_cast<Clock::duration>(
                                  std::chrono::duration<double>(frame.captured_s + frame.timeline.output / 1000.0));
  }
  if (frame.animation_s >= 0) {
    const std::int64_t offset = Nanoseconds(shown.time_since_epoch()) -
                                static_cast<std::int64_t>(std::llround(frame.animation_s * 1e9));
    if (offsets_ns_.size() < kOffsetFrames) {
      offsets_ns_.push_back(offset);
    } else {
      offsets_ns_[next_offset_] = offset;
      next_offset_ = (next_offset_ + 1) % kOffsetFrames;
    }
  }
  {
    const std::lock_guard lock(mutex_);
    for (Pending& line : incoming_) lines_.push_back(std::move(line));
    incoming_.clear();
  }
  if (frame.animation_s >= 0) {
    if (!heard_.empty() && !heard_written_) {
      // Frame time 0 in the video, as a line's start (HandOver).
      const double video_s = static_cast<double>(frames_shown_) / fps_ - frame.animation_s;
      sink_.WriteAudio(std::llround(video_s * speech::SpokenLine::kSampleRate), heard_);
      heard_written_ = true;
    }
    for (Pending& line : lines_) HandOver(line, frame, shown);
  }
  ++frames_shown_;
  NoteDeviceFailure();
}

// Hands `line` to the player as soon as the offset is known (it is due at start_s + offset),
// and to the video on the first frame that reaches its start.
void SessionSound::HandOver(Pending& line, const FrameLog& frame, Clock::time_point shown) {
  const double start = line.utterance.start_s;
  if (line.to_player && !offsets_ns_.empty()) {
    const std::int64_t due_ns = MedianOf(offsets_ns_) + static_cast<std::int64_t>(std::llround(start * 1e9));
    audio::TimedClip clip;
    clip.id = line.sound.id;
    clip.samples = line.utterance.line->samples;
    clip.start = Clock::time_point(std::chrono::duration_cast<Clock::duration>(std::chrono::nanoseconds(due_ns)));
    player_->Play(std::move(clip));
    line.to_player = false;
  }
  if (frame.animation_s + kSameTime < start || line.sound.shown_s >= 0) return;
  line.sound.shown_s = SinceStart(shown);
  if (line.to_video) {
    // This frame is the frames_shown_-th of the video, shown at frames_shown_ / fps.
    const double video_s = static_cast<double>(frames_shown_) / fps_ + (start - frame.animation_s);
    sink_.WriteAudio(std::llround(video_s * speech::SpokenLine::kSampleRate), line.utterance.line->samples);
    line.to_video = false;
    line.sound.in_video = true;
  }
}

void SessionSound::NoteDeviceFailure() {
  if (!player_ || failure_noted_ || frames_shown_ % 15 != 0) return;
  const audio::PlayerStats stats = player_->Stats();
  if (stats.error.empty()) return;
  failure_noted_ = true;  // one line; the session goes on silent
  std::fprintf(stderr, "\nnote: %s\n", stats.error.c_str());
}

SoundReport SessionSound::Finish() {
  SoundReport report;
  report.playing = player_ != nullptr;
  report.video_track = sink_.HasAudio();
  if (report.video_track) report.video_samples_dropped = sink_.AudioSamplesDropped();
  if (heard_written_) report.heard_in_video_s = static_cast<double>(heard_.size()) / speech::SpokenLine::kSampleRate;
  {
    const std::lock_guard lock(mutex_);
    for (Pending& line : incoming_) lines_.push_back(std::move(line));
    incoming_.clear();
  }
  for (const Pending& line : lines_) report.lines.push_back(line.sound);
  if (!player_) return report;
  report.player = player_->Stats();
  for (const audio::ClipReport& r : player_->TakeReports()) {
    for (LineSound& line : report.lines) {
      if (line.id != r.id) continue;
      line.heard_s = SinceStart(r.heard);
      line.written_s = SinceStart(r.written);
      line.late = r.late;
    }
  }
  return report;
}

std::string SoundSummaryText(const SoundReport& r) {
  if (!r.playing && !r.video_track) return "";
  std::string out = "sound: " + std::to_string(r.lines.size()) + (r.lines.size() == 1 ? " line" : " lines");
  char part[320];
  if (r.playing) {
    std::size_t heard = 0;
    double worst_ms = 0;
    for (const LineSound& l : r.lines) {
      if (l.heard_s < 0 || l.shown_s < 0) continue;
      ++heard;
      const double ms = 1000 * (l.heard_s - l.shown_s);
      if (std::abs(ms) > std::abs(worst_ms)) worst_ms = ms;
    }
    std::snprintf(part, sizeof part, "; played %zu (%lld late), first samples heard within %+.1f ms of their frames' display; "
                  "%lld underruns (%lld in a line), player %s",
                  heard, static_cast<long long>(r.player.clips_late), worst_ms, static_cast<long long>(r.player.underruns),
                  static_cast<long long>(r.player.underruns_in_clips), r.player.scheduling.c_str());
    out += part;
    if (!r.player.error.empty()) out += "; " + r.player.error;
  }
  if (r.video_track) {
    std::size_t written = 0;
    for (const LineSound& l : r.lines) written += l.in_video;
    std::snprintf(part, sizeof part, "; %zu in the video's audio track", written);
    out += part;
    if (r.heard_in_video_s > 0) {
      std::snprintf(part, sizeof part, " with the %.1f s heard (--audio-in)", r.heard_in_video_s);
      out += part;
    }
    if (r.video_samples_dropped) out += " (" + std::to_string(r.video_samples_dropped) + " samples dropped)";
  }
  return out + "\n";
}

nlohmann::ordered_json SoundJson(const SoundReport& r) {
  nlohmann::ordered_json lines = nlohmann::ordered_json::array();
  for (const LineSound& l : r.lines) {
    nlohmann::ordered_json line = {{"id", l.id}, {"origin", l.origin}, {"start_s", l.start_s}, {"shown_s", l.shown_s}};
    if (r.playing) {
      line["heard_s"] = l.heard_s;
      line["written_s"] = l.written_s;
      line["late"] = l.late;
    }
    if (r.video_track) line["in_video"] = l.in_video;
    lines.push_back(line);
  }
  nlohmann::ordered_json j = {{"playing", r.playing}, {"video_track", r.video_track}, {"lines", lines}};
  if (r.playing) {
    j["underruns"] = r.player.underruns;
    j["underruns_in_lines"] = r.player.underruns_in_clips;
    j["player_scheduling"] = r.player.scheduling;
    j["clips_played"] = r.player.clips_played;
    j["clips_late"] = r.player.clips_late;
    j["clips_dropped"] = r.player.clips_dropped;
    if (r.player.least_queued != audio::Clock::duration::max())
      j["least_queued_ms"] = std::chrono::duration<double, std::milli>(r.player.least_queued).count();
    if (!r.player.error.empty()) j["error"] = r.player.error;
  }
  if (r.video_track) j["video_samples_dropped"] = r.video_samples_dropped;
  if (r.video_track) j["heard_in_video_s"] = r.heard_in_video_s;
  return j;
}

}  // namespace arview::app
