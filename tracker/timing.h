#pragma once

#include <time.h>

#include <chrono>

namespace arview::tracker {

inline double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// CPU time of the calling thread, milliseconds. With OpenCV single-threaded all of a frame's work
// runs on the caller's thread, so this is the frame's cost even when other processes compete
// for the cores (wall time then includes waiting).
inline double ThreadCpuMilliseconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

}  // namespace arview::tracker
