#include "audio/clip_player.h"

#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <optional>
#include <utility>

#include "audio/alsa_pcm.h"
#include "audio/audio_error.h"
#include "base/thread_priority.h"

namespace arview::audio {

namespace {

// Above every ordinary thread, and low among real-time ones (JACK runs its clients at 70 and
// more): the player only needs to wake before the device runs dry.
constexpr int kPlayerRealtimePriority = 20;

std::int64_t DurationToFrames(Clock::duration d) {
  return std::llround(std::chrono::duration<double>(d).count() * kSpeechRate);
}

std::int64_t MillisecondsToFrames(std::chrono::milliseconds ms) { return ms.count() * kSpeechRate / 1000; }

}  // namespace

struct ClipPlayer::Active {
  TimedClip clip;
  std::int64_t position = -1;  // the stream frame of its first sample; -1 until its period is written
  bool late = false;
};

ClipPlayer::ClipPlayer(const PlayerOptions& options)
    : device_(options.device),
      period_frames_(std::max<std::int64_t>(1, MillisecondsToFrames(options.period))),
      lead_(options.lead) {
  if (options.period.count() <= 0 || options.lead < options.period) {
    throw AudioError(DeviceLabel(PcmDirection::kPlayback, device_) + ": the lead (" + std::to_string(options.lead.count()) +
                     " ms) must be at least one period (" + std::to_string(options.period.count()) + " ms)");
  }
  // Room for the lead and two periods more, so that a write never waits on the device.
  const auto buffer = static_cast<snd_pcm_uframes_t>(MillisecondsToFrames(options.lead) + 2 * period_frames_);
  pcm_ = std::make_unique<OpenedPcm>(
      OpenSpeechPcm(device_, PcmDirection::kPlayback, static_cast<snd_pcm_uframes_t>(period_frames_), buffer));
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
}

ClipPlayer::~ClipPlayer() {
  RequestStop();
  Join();
}

void ClipPlayer::Join() {
  if (thread_.joinable()) thread_.join();
}

void ClipPlayer::Play(TimedClip clip) {
  if (clip.samples.empty()) return;
  std::lock_guard lock(mutex_);
  if (terminated_) {
    ++stats_.clips_dropped;
    return;
  }
  incoming_.push_back(std::move(clip));
  ++clips_in_flight_;
}

PlayerStats ClipPlayer::Stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

std::vector<ClipReport> ClipPlayer::TakeReports() {
  std::lock_guard lock(mutex_);
  return std::exchange(reports_, {});
}

bool ClipPlayer::Idle() const {
  std::lock_guard lock(mutex_);
  return clips_in_flight_ == 0;
}

// Whether a clip had started before the frame at `position`: a starved device then cuts into it.
bool ClipPlayer::ClipSoundingBefore(const std::vector<Active>& active, std::int64_t position) {
  return std::any_of(active.begin(), active.end(), [&](const Active& a) { return a.position >= 0 && a.position < position; });
}

void ClipPlayer::WritePeriod(std::vector<Active>& active, std::int64_t position, TimePoint heard_next,
                             std::optional<Clock::duration> queued, std::vector<std::int16_t>& period) {
  std::fill(period.begin(), period.end(), std::int16_t{0});
  std::vector<const Active*> starting;
  for (Active& a : active) {
    if (a.position < 0) {
      std::int64_t offset = DurationToFrames(a.clip.start - heard_next);
      if (offset >= period_frames_) continue;  // due in a later period
      if (offset < 0) {
        a.late = true;
        offset = 0;
      }
      a.position = position + offset;
      starting.push_back(&a);
    }
    const auto size = static_cast<std::int64_t>(a.clip.samples.size());
    const std::int64_t from = std::max(position, a.position);
    const std::int64_t to = std::min(position + period_frames_, a.position + size);
    for (std::int64_t f = from; f < to; ++f) {
      const int sum = period[static_cast<std::size_t>(f - position)] + a.clip.samples[static_cast<std::size_t>(f - a.position)];
      period[static_cast<std::size_t>(f - position)] = static_cast<std::int16_t>(std::clamp(sum, -32768, 32767));
    }
  }
  snd_pcm_t* pcm = pcm_->pcm.get();
  std::int64_t done = 0;
  std::int64_t underruns = 0;
  while (done < period_frames_) {
    const snd_pcm_sframes_t n = snd_pcm_writei(pcm, period.data() + done, static_cast<snd_pcm_uframes_t>(period_frames_ - done));
    if (n >= 0) {
      done += n;
      continue;
    }
    const int error = static_cast<int>(n);
    if (!IsRecoverable(error) || snd_pcm_recover(pcm, error, 1) < 0) {
      throw AudioError(PcmFaultLine(PcmDirection::kPlayback, device_, error));
    }
    if (error == -EPIPE) ++underruns;
  }
  const TimePoint written = Clock::now();
  std::lock_guard lock(mutex_);
  if (queued) stats_.least_queued = std::min(stats_.least_queued, *queued);
  stats_.frames_written += period_frames_;
  stats_.underruns += underruns;
  if (ClipSoundingBefore(active, position)) stats_.underruns_in_clips += underruns;
  for (const Active* a : starting) {
    reports_.push_back(ClipReport{a->clip.id, a->clip.start, heard_next + SpeechDuration(a->position - position), written, a->late});
    if (a->late) ++stats_.clips_late;
  }
}

void ClipPlayer::Run(const std::stop_token& stop) {
  pthread_setname_np(pthread_self(), "arview-play");  // shown by top -H
  // The device runs dry when this thread wakes later than the lead (100 ms): under a load of
  // 20 on two cores an ordinary thread woke 206 ms late (docs/speech.md). It writes 10 ms a
  // wake-up and sleeps between, so it may preempt the others.
  const std::string scheduling = RaiseCurrentThreadForTiming(kPlayerRealtimePriority);
  {
    std::lock_guard lock(mutex_);
    stats_.scheduling = scheduling;
  }
  snd_pcm_t* pcm = pcm_->pcm.get();
  std::vector<Active> active;
  std::vector<std::int16_t> period(static_cast<std::size_t>(period_frames_));
  std::int64_t position = 0;
  // For a device that reports no delay: when the next frame will be heard, by the player's count.
  std::optional<TimePoint> counted_next;
  bool device_reports_delay = false;
  bool lead_reached = false;  // the queue was filled up to the lead once
  try {
    while (!stop.stop_requested()) {
      snd_pcm_sframes_t delay = 0;
      if (const int error = snd_pcm_delay(pcm, &delay); error < 0) {
        if (!IsRecoverable(error) || snd_pcm_recover(pcm, error, 1) < 0) {
          throw AudioError(PcmFaultLine(PcmDirection::kPlayback, device_, error));
        }
        if (error == -EPIPE) {
          std::lock_guard lock(mutex_);
          ++stats_.underruns;
          if (ClipSoundingBefore(active, position)) ++stats_.underruns_in_clips;
        }
        continue;
      }
      const TimePoint now = Clock::now();
      if (delay > 0) device_reports_delay = true;
      TimePoint heard_next = now + SpeechDuration(std::max<snd_pcm_sframes_t>(delay, 0));
      TimePoint queue_end = heard_next;  // where the queue ends, by ALSA or by the count
      if (!device_reports_delay && counted_next) {
        queue_end = *counted_next;
        if (*counted_next < now) {
          std::lock_guard lock(mutex_);
          ++stats_.underruns;  // by the count, the queue ran dry before this write
          if (ClipSoundingBefore(active, position)) ++stats_.underruns_in_clips;
        } else {
          heard_next = *counted_next;
        }
      }
      if (heard_next - now > lead_) {
        lead_reached = true;
        std::unique_lock lock(mutex_);
        wake_.wait_until(lock, stop, heard_next - lead_, [] { return false; });
        continue;
      }
      {
        std::lock_guard lock(mutex_);
        while (!incoming_.empty()) {
          active.push_back(Active{std::move(incoming_.front()), -1, false});
          incoming_.pop_front();
        }
      }
      WritePeriod(active, position, heard_next, lead_reached ? std::optional(queue_end - now) : std::nullopt, period);
      position += period_frames_;
      counted_next = heard_next + SpeechDuration(period_frames_);
      const auto finished = std::erase_if(active, [&](const Active& a) {
        return a.position >= 0 && a.position + static_cast<std::int64_t>(a.clip.samples.size()) <= position;
      });
      if (finished > 0) {
        std::lock_guard lock(mutex_);
        stats_.clips_played += static_cast<std::int64_t>(finished);
        clips_in_flight_ -= static_cast<std::int64_t>(finished);
      }
    }
  } catch (const std::exception& error) {
    std::lock_guard lock(mutex_);
    stats_.error = error.what();
  }
  std::lock_guard lock(mutex_);
  if (!stats_.error.empty()) {
    stats_.clips_dropped += static_cast<std::int64_t>(active.size() + incoming_.size());
    clips_in_flight_ = 0;
    incoming_.clear();
  }
  terminated_ = true;
}

}  // namespace arview::audio
