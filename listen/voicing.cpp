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

bool FrameIsVoiced(const std::vector<double>& x, std::size_t start) {
  double energy = 0;
  for (std::size_t i = start; i < start + kFrame; ++i) energy += x[i] * x[i];
  if (std::sqrt(energy / kFrame) < kQuietRms) return false;
  // The frame against the frame `lag` samples later (x holds kMaxLag samples beyond every
  // frame); the later frame's energy slides along with the lag.
  double tail = 0;
  for (std::size_t i = start + kMinLag; i < start + kMinLag + kFrame; ++i) tail += x[i] * x[i];
  for (std::size_t lag = kMinLag; lag <= kMaxLag; ++lag) {
    double cross = 0;
    for (std::size_t i = start; i < start + kFrame; ++i) cross += x[i] * x[i + lag];
    if (tail > 0 && cross / std::sqrt(energy * tail) > kVoicedCorrelation) return true;
    if (lag < kMaxLag) tail += x[start + lag + kFrame] * x[start + lag + kFrame] - x[start + lag] * x[start + lag];
  }
  return false;
}

}  // namespace

double VoicedFraction(std::span<const std::int16_t> samples) {
  if (samples.size() < kFrame + kMaxLag) return 0;
  // Pre-emphasis (1 − 0.97 z⁻¹): flattens the low-frequency weight of pink and room noise, whose
  // slow swings would otherwise correlate at every lag, while pitch pulses stay periodic.
  std::vector<double> x(samples.size());
  x[0] = samples[0];
  for (std::size_t i = 1; i < samples.size(); ++i) x[i] = samples[i] - 0.97 * samples[i - 1];
  std::size_t frames = 0;
  std::size_t voiced = 0;
  for (std::size_t start = 0; start + kFrame + kMaxLag <= x.size(); start += kHop) {
    ++frames;
    if (FrameIsVoiced(x, start)) ++voiced;
  }
  return static_cast<double>(voiced) / static_cast<double>(frames);
}

}  // namespace arview::listen
