#pragma once
// The accept/reject test of a tracked pose, following the noise actually observed: the largest
// accepted inlier RMS is `factor` times a robust running estimate of the residual scale (the
// median RMS of the last `window` accepted tracked frames), bounded to [min_px, max_px]. A camera
// whose genuine poses fit at 0.4 px then refuses a 1.2 px fit (drifted flow, wrong guided
// matches), one that fits at 0.9 px (JPEG, blur) is not refused at 1.6 px; the bounds keep one
// bad stretch from opening the gate.

#include <cstddef>
#include <vector>

namespace arview::tracker {

struct ResidualGateOptions {
  double factor = 2.0;
  double min_px = 1.0;
  double max_px = 2.5;
  double initial_scale_px = 0.75;  // before any tracked frame: gate = 1.5 px
  int window = 30;
  // Until this many frames were observed the scale is not set below initial_scale_px: the
  // median of three clean frames is no robust scale, and a gate closed by it refused the fourth
  // frame of a phone clip whose residuals grew from 0.6 to 1.2 px as it turned.
  int min_observations = 10;
};

class ResidualGate {
 public:
  explicit ResidualGate(const ResidualGateOptions& options = {});
  // The largest inlier RMS (working pixels) a tracked pose may have now.
  double Gate() const { return gate_; }
  double Scale() const { return scale_; }
  // An accepted pose's inlier RMS.
  void Observe(double rms_px);
  const ResidualGateOptions& options() const { return options_; }

 private:
  ResidualGateOptions options_;
  std::vector<double> recent_;  // ring buffer of the last `window` RMS values
  std::size_t next_ = 0;
  int observed_ = 0;  // accepted frames so far
  double scale_ = 0;
  double gate_ = 0;
};

}  // namespace arview::tracker
