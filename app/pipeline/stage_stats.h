#pragma once
// Per-stage timings of the real-time pipeline: each stage records how long it took for each
// frame; the summary (base/stats.h) gives the median and 95th percentile that stats.json and the
// console show. Constant memory (base/stats.h, StreamingSummary): exact figures for the first
// 8,192 frames of a stage, then count, mean and max exact and the quantiles within 1%, so that
// a session that runs all day holds no more than one that ran a few minutes.

#include <chrono>
#include <map>
#include <mutex>
#include <string>

#include "base/stats.h"

namespace arview::app {

// Milliseconds, summarised by base/stats.h (median, p95, mean, max, count, ...).
using TimingSummary = Summary;

// Each pipeline stage owns one and records into it on its own thread; the owner reads the
// summaries after joining it. Thread-safe all the same (a lock no other thread contends).
class StageStats {
 public:
  void Record(const std::string& stage, double ms);
  std::map<std::string, TimingSummary> Summaries() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, StreamingSummary> summaries_;
};

// Times one stage's work on one frame: records the milliseconds from its construction to the end
// of its scope under `stage`.
class ScopedStageTimer {
 public:
  ScopedStageTimer(StageStats& stats, std::string stage)
      : stats_(stats), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStageTimer() {
    stats_.Record(stage_, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count());
  }

 private:
  StageStats& stats_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace arview::app
