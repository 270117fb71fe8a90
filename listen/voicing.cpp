#include "listen/voicing.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace arview::listen {
namespace {

constexpr std::size_t kFrame = 400;     // 25 ms at 16 kHz
constexpr std::size_t kHop = 160;       // 10 ms
constexpr std::size_t kMinLag = 40;     // 2.5 ms: 400 Hz
constexpr std::size_t kMaxLag = 320;    // 20 ms: 50 Hz
constexpr double kVoicedCorrelation = 0.5;
constexpr double kQuietRms = 327.68;    // 1% of full scale

// The lag at which the frame at `start` correlates best with itself, when that correlation
// passes kVoicedCorrelation; 0 for an unvoiced or quiet frame.
std::size_t PitchLag(const std::vector<double>& x, std::size_t start) {
  double energy = 0;
  for (std::size_t i = start; i < start + kFrame; ++i) energy += x[i] * x[i];
  if (std::sqrt(energy / kFrame) < kQuietRms) return 0;
  // The frame against the frame `lag` samples later (x holds kMaxLag samples beyond every
  // frame); the later frame's energy slides along with the lag.
  double tail = 0;
  for (std::size_t i = start + kMinLag; i < start + kMinLag + kFrame; ++i) tail += x[i] * x[i];
  double best = kVoicedCorrelation;
  std::size_t best_lag = 0;
  for (std::size_t lag = kMinLag; lag <= kMaxLag; ++lag) {
    double cross = 0;
    for (std::size_t i = start; i < start + kFrame; ++i) cross += x[i] * x[i + lag];
    if (tail > 0 && cross / std::sqrt(energy * tail) > best) {
      best = cross / std::sqrt(energy * tail);
      best_lag = lag;
    }
    if (lag < kMaxLag) tail += x[start + lag + kFrame] * x[start + lag + kFrame] - x[start + lag] * x[start + lag];
  }
  return best_lag;
}

}  // namespace

Voicing MeasureVoicing(std::span<const std::int16_t> samples) {
  Voicing voicing;
  if (samples.size() < kFrame + kMaxLag) return voicing;
  // Pre-emphasis (1 − 0.97 z⁻¹): flattens the low-frequency weight of pink and room noise, whose
  // slow swings would otherwise correlate at every lag, while pitch pulses stay periodic.
  std::vector<double> x(samples.size());
  x[0] = samples[0];
  for (std::size_t i = 1; i < samples.size(); ++i) x[i] = samples[i] - 0.97 * samples[i - 1];
  std::size_t frames = 0;
  std::size_t voiced = 0;
  std::size_t run = 0;
  std::size_t longest_run = 0;
  std::size_t previous_lag = 0;
  for (std::size_t start = 0; start + kFrame + kMaxLag <= x.size(); start += kHop) {
    ++frames;
    const std::size_t lag = PitchLag(x, start);
    if (lag != 0) ++voiced;
    run = lag != 0 && lag == previous_lag ? run + 1 : (lag != 0 ? 1 : 0);
    longest_run = std::max(longest_run, run);
    previous_lag = lag;
  }
  voicing.voiced_fraction = static_cast<double>(voiced) / static_cast<double>(frames);
  voicing.longest_steady_pitch_s = static_cast<double>(longest_run * kHop) / 16000.0;
  return voicing;
}

}  // namespace arview::listen
