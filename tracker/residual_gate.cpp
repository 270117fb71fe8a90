#include "tracker/residual_gate.h"

#include <algorithm>
#include <cmath>

#include "base/stats.h"

namespace arview::tracker {

ResidualGate::ResidualGate(const ResidualGateOptions& options)
    : options_(options), scale_(options.initial_scale_px) {
  options_.window = std::max(1, options_.window);
  gate_ = std::clamp(options_.factor * scale_, options_.min_px, options_.max_px);
}

void ResidualGate::Observe(double rms_px) {
  if (!std::isfinite(rms_px) || rms_px < 0) return;
  if (recent_.size() < static_cast<std::size_t>(options_.window)) {
    recent_.push_back(rms_px);
  } else {
    recent_[next_] = rms_px;
    next_ = (next_ + 1) % recent_.size();
  }
  ++observed_;
  scale_ = Median(recent_);
  if (observed_ < options_.min_observations) scale_ = std::max(scale_, options_.initial_scale_px);
  gate_ = std::clamp(options_.factor * scale_, options_.min_px, options_.max_px);
}

}  // namespace arview::tracker
