#pragma once
// One Euro filter (Casiez, Roussel, Vogel, CHI 2012) on a 3-vector, used to smooth the camera
// centre that drives the character's animation. Jitter is removed at low speed (min_cutoff),
// lag is reduced at high speed (beta). The raw pose still places the character in the image.

#include <Eigen/Core>

#include "base/option_check.h"

namespace arview::tracker {

struct OneEuroOptions {
  double min_cutoff_hz = 1.0;  // cutoff at rest: lower = smoother, more lag
  // Cutoff growth per unit of speed (units/s): higher = less lag. 5: the smoothed centre trails
  // the raw one by under a frame on the demo's lap, and on real footage (templeRing, phone-fox)
  // it stays 2.7-6.6x closer to the truth than with 0.5 (docs/tracker.md, "Registration as the
  // viewer sees it", "The One Euro filter's beta on real footage").
  double beta = 5.0;
  double derivative_cutoff_hz = 1.0;

  // Throws OptionError naming the first bad field (base/option_check.h; tracker/tracker_options.cpp).
  void Check(const OptionNames& names = {}) const;
};

class OneEuroFilter {
 public:
  explicit OneEuroFilter(const OneEuroOptions& options = {}) : options_(options) {}
  // Time must increase; a non-increasing time restarts the filter at `x`.
  Eigen::Vector3d Filter(const Eigen::Vector3d& x, double time_s);
  void Reset() { initialised_ = false; }
  const OneEuroOptions& options() const { return options_; }

 private:
  OneEuroOptions options_;
  bool initialised_ = false;
  double last_time_ = 0;
  Eigen::Vector3d x_hat_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d dx_hat_ = Eigen::Vector3d::Zero();
};

}  // namespace arview::tracker
