#include "app/pipeline/stage_stats.h"

namespace arview::app {

void StageStats::Record(const std::string& stage, double ms) {
  std::lock_guard lock(mutex_);
  summaries_[stage].Add(ms);
}

std::map<std::string, TimingSummary> StageStats::Summaries() const {
  std::lock_guard lock(mutex_);
  std::map<std::string, TimingSummary> out;
  for (const auto& [stage, samples] : summaries_) out[stage] = samples.Get();
  return out;
}

}  // namespace arview::app
