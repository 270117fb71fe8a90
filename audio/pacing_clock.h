#pragma once
// The clock an audio source is paced by: real time for a microphone or a paced replay, a clock
// of the caller's (a replay's media time, a test's) for a WAV file. Sources and the player use
// TimePoint (audio/pcm.h) for every sample time.

#include <condition_variable>
#include <mutex>
#include <stop_token>

#include "audio/pcm.h"

namespace arview::audio {

class PacingClock {
 public:
  virtual ~PacingClock() = default;
  virtual TimePoint Now() const = 0;
  // Returns at `when` (at once when it has passed), or early with false once `stop` is requested.
  virtual bool SleepUntil(TimePoint when, const std::stop_token& stop) = 0;
};

// std::chrono::steady_clock, slept on with a stop-aware wait. Any thread may use one instance.
class SteadyPacingClock final : public PacingClock {
 public:
  TimePoint Now() const override { return Clock::now(); }
  bool SleepUntil(TimePoint when, const std::stop_token& stop) override;

 private:
  std::mutex mutex_;
  std::condition_variable_any wake_;
};

}  // namespace arview::audio
