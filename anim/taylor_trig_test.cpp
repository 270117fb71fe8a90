#include "anim/taylor_trig.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arview::anim {
namespace {

TEST(TaylorTrig, MatchesLibmOnMinusHalfPiToHalfPi) {
  double worst = 0;
  for (int i = -100000; i <= 100000; ++i) {
    const double x = M_PI / 2 * i / 100000.0, y = M_PI / 2 * (100000 - std::abs(i)) / 100000.0;
    const Eigen::Array2d s = TaylorSin2(x, y), sc = TaylorSinCos(x);
    worst = std::max({worst, std::abs(s[0] - std::sin(x)), std::abs(s[1] - std::sin(y)), std::abs(sc[0] - std::sin(x)),
                      std::abs(sc[1] - std::cos(x))});
  }
  EXPECT_LT(worst, 4e-16);
  // Exact where it matters most: zero, and tiny arguments to the last bit.
  EXPECT_EQ(TaylorSinCos(0.0)[0], 0.0);
  EXPECT_EQ(TaylorSinCos(0.0)[1], 1.0);
  EXPECT_EQ(TaylorSin2(1e-9, -1e-12)[0], std::sin(1e-9));
  EXPECT_EQ(TaylorSin2(1e-9, -1e-12)[1], std::sin(-1e-12));
}

}  // namespace
}  // namespace arview::anim
