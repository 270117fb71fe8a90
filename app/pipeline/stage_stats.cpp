#include "app/pipeline/stage_stats.h"

namespace arview::app {

void StageStats::Record(const std::string& stage, double ms) {
  std::lock_guard lock(mutex_);
  samples_[stage].push_back(ms);
}

std::map<std::string, TimingSummary> StageStats::Summaries() const {
  std::lock_guard lock(mutex_);
  std::map<std::string, TimingSummary> out;
  for (const auto& [stage, samples] : samples_) out[stage] = Summarize(samples);
  return out;
}

}  // namespace arview::app
