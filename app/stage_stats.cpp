#include "app/stage_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace arview::app {

TimingSummary Summarize(std::vector<double> samples) {
  TimingSummary s;
  s.count = samples.size();
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  // Nearest-rank percentiles: every reported figure is a measured sample.
  auto rank = [&](double p) {
    const size_t r = static_cast<size_t>(std::ceil(p * samples.size()));
    return samples[std::clamp<size_t>(r, 1, samples.size()) - 1];
  };
  s.median_ms = rank(0.5);
  s.p95_ms = rank(0.95);
  s.mean_ms = std::accumulate(samples.begin(), samples.end(), 0.0) / samples.size();
  s.max_ms = samples.back();
  return s;
}

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
