#include "audio/resample.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "audio/audio_error.h"
#include "audio/wav.h"

namespace arview::audio {

namespace {

constexpr int kZeroCrossings = 16;
constexpr int kTablePointsPerCrossing = 512;
constexpr double kKaiserBeta = 8.6;
constexpr double kCutoffOfNyquist = 0.9;

// The zeroth-order modified Bessel function of the first kind, by its power series.
double BesselI0(double x) {
  double sum = 1.0;
  double term = 1.0;
  for (int k = 1; k < 50; ++k) {
    term *= (x / (2.0 * k)) * (x / (2.0 * k));
    sum += term;
    if (term < sum * 1e-17) break;
  }
  return sum;
}

// sinc(u)·kaiser(u / kZeroCrossings) for u in [0, kZeroCrossings], u in zero crossings.
const std::vector<double>& KernelTable() {
  static const std::vector<double> table = [] {
    std::vector<double> values(kZeroCrossings * kTablePointsPerCrossing + 2, 0.0);
    const double norm = BesselI0(kKaiserBeta);
    for (std::size_t i = 0; i + 1 < values.size(); ++i) {
      const double u = static_cast<double>(i) / kTablePointsPerCrossing;
      const double r = u / kZeroCrossings;
      const double sinc = u == 0.0 ? 1.0 : std::sin(std::numbers::pi * u) / (std::numbers::pi * u);
      values[i] = r >= 1.0 ? 0.0 : sinc * BesselI0(kKaiserBeta * std::sqrt(1.0 - r * r)) / norm;
    }
    return values;
  }();
  return table;
}

double Kernel(const std::vector<double>& table, double u) {
  const double x = std::abs(u) * kTablePointsPerCrossing;
  const auto i = static_cast<std::size_t>(x);
  if (i + 1 >= table.size()) return 0.0;
  const double f = x - static_cast<double>(i);
  return table[i] + f * (table[i + 1] - table[i]);
}

void RequireRate(int rate) {
  if (rate < kMinWavRate || rate > kMaxWavRate) {
    throw AudioError("audio: cannot resample at " + std::to_string(rate) + " Hz (outside " + std::to_string(kMinWavRate) +
                     " to " + std::to_string(kMaxWavRate) + ")");
  }
}

}  // namespace

std::vector<std::int16_t> Resample(std::span<const std::int16_t> samples, int from_rate, int to_rate) {
  RequireRate(from_rate);
  RequireRate(to_rate);
  if (from_rate == to_rate) return {samples.begin(), samples.end()};
  const std::vector<double>& table = KernelTable();
  // The cutoff as a fraction of the input's Nyquist frequency: below both rates' Nyquist.
  const double fc = kCutoffOfNyquist * std::min(1.0, static_cast<double>(to_rate) / from_rate);
  const double half_width = kZeroCrossings / fc;  // in input samples
  const auto n_in = static_cast<std::int64_t>(samples.size());
  const std::int64_t n_out = n_in * to_rate / from_rate;
  std::vector<std::int16_t> out(static_cast<std::size_t>(n_out));
  for (std::int64_t j = 0; j < n_out; ++j) {
    // The exact input position of output sample j, from integers so that no error accumulates.
    const double t = static_cast<double>(j * from_rate) / to_rate;
    const auto first = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(t - half_width)));
    const auto last = std::min<std::int64_t>(n_in - 1, static_cast<std::int64_t>(std::floor(t + half_width)));
    double sum = 0.0;
    for (std::int64_t k = first; k <= last; ++k) sum += samples[static_cast<std::size_t>(k)] * Kernel(table, fc * (t - k));
    out[static_cast<std::size_t>(j)] = static_cast<std::int16_t>(std::clamp(std::lround(fc * sum), -32768L, 32767L));
  }
  return out;
}

std::vector<std::int16_t> DownmixToMono(const PcmAudio& audio) {
  if (audio.channels == 1) return audio.samples;
  if (audio.channels != 2) throw AudioError("audio: cannot downmix " + std::to_string(audio.channels) + " channels; only mono and stereo");
  std::vector<std::int16_t> mono(audio.frames());
  for (std::size_t i = 0; i < mono.size(); ++i) {
    mono[i] = static_cast<std::int16_t>((audio.samples[2 * i] + audio.samples[2 * i + 1]) / 2);
  }
  return mono;
}

std::vector<std::int16_t> ToSpeechFormat(const PcmAudio& audio) {
  return Resample(DownmixToMono(audio), audio.sample_rate, kSpeechRate);
}

}  // namespace arview::audio
