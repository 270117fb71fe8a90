#include "tracker/centre_fitter.h"

#include <Eigen/Dense>

namespace arview::tracker {

void CentreFitter::Add(double timestamp, const Eigen::Vector3d& centre) {
  samples_.emplace_back(timestamp, centre);
  while (!samples_.empty() && (static_cast<int>(samples_.size()) > max_count_ ||
                               !(timestamp - samples_.front().first <= max_span_s_)))
    samples_.erase(samples_.begin());
}

Eigen::Vector3d CentreFitter::At(double timestamp) const {
  if (samples_.empty()) return Eigen::Vector3d::Zero();
  double mean_t = 0;
  Eigen::Vector3d mean_c = Eigen::Vector3d::Zero();
  for (const auto& [t, c] : samples_) mean_t += t, mean_c += c;
  mean_t /= static_cast<double>(samples_.size());
  mean_c /= static_cast<double>(samples_.size());
  double stt = 0;
  Eigen::Vector3d stc = Eigen::Vector3d::Zero();
  for (const auto& [t, c] : samples_) stt += (t - mean_t) * (t - mean_t), stc += (t - mean_t) * (c - mean_c);
  if (stt < 1e-12) return mean_c;
  return mean_c + stc / stt * (timestamp - mean_t);
}

}  // namespace arview::tracker
