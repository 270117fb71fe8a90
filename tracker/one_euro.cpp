#include "tracker/one_euro.h"

#include <cmath>

namespace arview::tracker {
namespace {

double SmoothingFactor(double cutoff_hz, double dt) {
  const double tau = 1.0 / (2.0 * M_PI * cutoff_hz);
  return 1.0 / (1.0 + tau / dt);
}

}  // namespace

Eigen::Vector3d OneEuroFilter::Filter(const Eigen::Vector3d& x, double time_s) {
  if (!initialised_ || !(time_s > last_time_)) {
    initialised_ = true;
    last_time_ = time_s;
    x_hat_ = x;
    dx_hat_.setZero();
    return x_hat_;
  }
  const double dt = time_s - last_time_;
  last_time_ = time_s;
  const Eigen::Vector3d dx = (x - x_hat_) / dt;
  const double a_d = SmoothingFactor(options_.derivative_cutoff_hz, dt);
  dx_hat_ = a_d * dx + (1 - a_d) * dx_hat_;
  const double cutoff = options_.min_cutoff_hz + options_.beta * dx_hat_.norm();
  const double a = SmoothingFactor(cutoff, dt);
  x_hat_ = a * x + (1 - a) * x_hat_;
  return x_hat_;
}

}  // namespace arview::tracker
