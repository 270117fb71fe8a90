#include "audio/pacing_clock.h"

namespace arview::audio {

bool SteadyPacingClock::SleepUntil(TimePoint when, const std::stop_token& stop) {
  std::unique_lock lock(mutex_);
  // Nothing ever notifies wake_ but a stop request: the wait ends at `when` or on the stop.
  wake_.wait_until(lock, stop, when, [] { return false; });
  return !stop.stop_requested();
}

}  // namespace arview::audio
