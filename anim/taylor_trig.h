#pragma once
// sin and cos on [−π/2, π/2] from their Taylor series, two values at once in a pair of SSE2
// lanes, always inlined: for the per-frame paths that need them for every joint (slerp between
// clip keys, rotation vectors to quaternions), ~25 instructions for both against ~40–150 per
// libm call. Error below 4e-16: the first omitted terms, x²³/23! and x²²/22!, are below 2e-17 at
// π/2, the rest is rounding (taylor_trig_test.cpp checks against libm).

#include <Eigen/Core>

namespace arview::anim {

namespace taylor_trig_detail {
// 1/(2k+1)! and 1/(2k)! with alternating signs, k = 10 down to 0.
inline constexpr double kSin[] = {1.0 / 51090942171709440000.0, -1.0 / 121645100408832000.0, 1.0 / 355687428096000.0,
                                  -1.0 / 1307674368000.0,       1.0 / 6227020800.0,          -1.0 / 39916800.0,
                                  1.0 / 362880.0,               -1.0 / 5040.0,               1.0 / 120.0,
                                  -1.0 / 6.0,                   1.0};
inline constexpr double kCos[] = {1.0 / 2432902008176640000.0, -1.0 / 6402373705728000.0, 1.0 / 20922789888000.0,
                                  -1.0 / 87178291200.0,        1.0 / 479001600.0,         -1.0 / 3628800.0,
                                  1.0 / 40320.0,               -1.0 / 720.0,              1.0 / 24.0,
                                  -1.0 / 2.0,                  1.0};
}  // namespace taylor_trig_detail

// (sin x, sin y) for x, y in [−π/2, π/2].
[[gnu::always_inline]] inline Eigen::Array2d TaylorSin2(double x, double y) {
  using taylor_trig_detail::kSin;
  const Eigen::Array2d v(x, y), u = v * v;
  Eigen::Array2d p = Eigen::Array2d::Constant(kSin[0]);
  for (int k = 1; k < 11; ++k) p = p * u + kSin[k];
  return v * p;
}

// (sin x, cos x) for x in [−π/2, π/2].
[[gnu::always_inline]] inline Eigen::Array2d TaylorSinCos(double x) {
  using taylor_trig_detail::kCos;
  using taylor_trig_detail::kSin;
  const double u = x * x;
  Eigen::Array2d p(kSin[0], kCos[0]);
  for (int k = 1; k < 11; ++k) p = p * u + Eigen::Array2d(kSin[k], kCos[k]);
  p[0] *= x;
  return p;
}

}  // namespace arview::anim
