#pragma once
// Seeded random draws that are the same on every platform: the standard leaves the algorithms
// of its distribution objects open, so replays (idle.h, balance_shift.h) draw through these from
// a std::mt19937_64, whose output the standard fixes.

#include <cstdint>
#include <random>
#include <vector>

namespace arview::anim {

// A draw in [0, 1): the generator's top 53 bits.
inline double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0); }

// An index drawn in proportion to `weights` (non-negative, not all zero).
template <class Weights>
int Draw(std::mt19937_64& rng, const Weights& weights) {
  double total = 0;
  for (double w : weights) total += w;
  double x = Uniform(rng) * total;
  int i = 0;
  for (double w : weights) {
    if (x < w) return i;
    x -= w;
    ++i;
  }
  return i - 1;
}

}  // namespace arview::anim
