#pragma once
// Events per second over a sliding window of time (at least the last two events are kept): the
// live output rate of the window's title and the HUD, and a camera's capture rate. Not
// thread-safe: one thread adds and reads.

#include <chrono>
#include <cstddef>
#include <deque>

namespace arview::app {

class RecentRate {
 public:
  using Clock = std::chrono::steady_clock;
  explicit RecentRate(Clock::duration window) : window_(window) {}

  void Add(Clock::time_point at) {
    times_.push_back(at);
    while (times_.size() > 2 && at - times_.front() > window_) times_.pop_front();
  }
  // 0 until two events are in the window.
  double PerSecond() const {
    if (times_.size() < 2) return 0;
    const double seconds = std::chrono::duration<double>(times_.back() - times_.front()).count();
    return seconds > 0 ? (times_.size() - 1) / seconds : 0;
  }
  // The events in the window (the latest ones): a caller keeping a value per event trims to it.
  std::size_t size() const { return times_.size(); }

 private:
  Clock::duration window_;
  std::deque<Clock::time_point> times_;
};

}  // namespace arview::app
