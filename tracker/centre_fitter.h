#pragma once
// The camera centre of recent frames fitted with a straight line, for the tracker's whip-pan
// frames (TrackingOptions::align_max_seconds).

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace arview::tracker {

// The camera centre extrapolated along a straight line (constant velocity in the world) fitted by
// least squares to the last few centres: a head or a phone keeps walking while it turns, which
// the per-frame relative motion (a velocity in the camera's turning frame) would bend, and the
// fit damps one noisy pose (a relocalization in a blurred frame).
class CentreFitter {
 public:
  explicit CentreFitter(int max_count = 64, double max_span_s = 0.5) : max_count_(max_count), max_span_s_(max_span_s) {}
  void Add(double timestamp, const Eigen::Vector3d& centre);
  void Clear() { samples_.clear(); }
  bool empty() const { return samples_.empty(); }
  // The fitted line at `timestamp` (the one centre when only one is known).
  Eigen::Vector3d At(double timestamp) const;

 private:
  int max_count_;
  double max_span_s_;
  std::vector<std::pair<double, Eigen::Vector3d>> samples_;  // oldest first
};

}  // namespace arview::tracker
