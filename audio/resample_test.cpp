#include "audio/resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "audio/audio_error.h"

namespace arview::audio {
namespace {

std::vector<std::int16_t> Tone(double hz, int rate, double seconds, double amplitude) {
  std::vector<std::int16_t> samples(static_cast<std::size_t>(seconds * rate));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i] = static_cast<std::int16_t>(std::lround(amplitude * std::sin(2 * std::numbers::pi * hz * static_cast<double>(i) / rate)));
  }
  return samples;
}

// The RMS of the middle half (away from the edges, where the filter sees zeros).
double MiddleRms(const std::vector<std::int16_t>& samples) {
  double sum = 0;
  const std::size_t from = samples.size() / 4;
  const std::size_t to = 3 * samples.size() / 4;
  for (std::size_t i = from; i < to; ++i) sum += static_cast<double>(samples[i]) * samples[i];
  return std::sqrt(sum / static_cast<double>(to - from));
}

double GainDb(double hz, int from, int to) {
  const auto in = Tone(hz, from, 1.0, 16000);
  return 20 * std::log10(MiddleRms(Resample(in, from, to)) / MiddleRms(in));
}

TEST(Resample, LengthIsTheInputsTimesTheRatioRoundedDown) {
  EXPECT_EQ(Resample(std::vector<std::int16_t>(44100), 44100, 16000).size(), 16000u);
  EXPECT_EQ(Resample(std::vector<std::int16_t>(441), 44100, 16000).size(), 160u);
  EXPECT_EQ(Resample(std::vector<std::int16_t>(8000), 8000, 16000).size(), 16000u);
  EXPECT_TRUE(Resample({}, 48000, 16000).empty());
}

TEST(Resample, TheSameRateIsACopy) {
  const auto in = Tone(440, 16000, 0.1, 1000);
  EXPECT_EQ(Resample(in, 16000, 16000), in);
}

// docs/audio.md's table comes from these figures (printed).
TEST(Resample, SpeechBandPassesAndWhatTheNewRateCannotHoldIsRemoved) {
  for (const int from : {44100, 48000, 22050}) {
    std::printf("%d -> 16000 Hz: 7000 Hz tone %+.2f dB, 7500 Hz %+.2f dB (the transition band)\n", from,
                GainDb(7000, from, 16000), GainDb(7500, from, 16000));
    for (const double hz : {300.0, 1000.0, 3400.0, 6000.0}) {
      const double gain = GainDb(hz, from, 16000);
      std::printf("%d -> 16000 Hz: %.0f Hz tone %+.3f dB\n", from, hz, gain);
      EXPECT_NEAR(gain, 0.0, 0.1) << from << " Hz, " << hz << " Hz tone";
    }
    for (const double hz : {8800.0, 10000.0, from / 2.0 - 500}) {
      const double gain = GainDb(hz, from, 16000);
      std::printf("%d -> 16000 Hz: %.0f Hz tone %+.1f dB\n", from, hz, gain);
      EXPECT_LT(gain, -80.0) << from << " Hz, " << hz << " Hz tone (aliasing)";
    }
  }
}

TEST(Resample, UpsamplingKeepsATone) {
  const double gain = GainDb(1000, 8000, 16000);
  EXPECT_NEAR(gain, 0.0, 0.1);
  // The tone is where it was: zero crossings 8 samples apart at 16 kHz.
  const auto out = Resample(Tone(1000, 8000, 0.5, 10000), 8000, 16000);
  for (std::size_t i = 1000; i < 1100; ++i) {
    EXPECT_NEAR(out[i], 10000 * std::sin(2 * std::numbers::pi * 1000.0 * static_cast<double>(i) / 16000), 30) << i;
  }
}

TEST(Resample, StereoIsTheMeanOfItsChannels) {
  const PcmAudio stereo{16000, 2, {100, 300, -5, -6, 32767, 32767}};
  EXPECT_EQ(DownmixToMono(stereo), (std::vector<std::int16_t>{200, -5, 32767}));
  EXPECT_EQ(ToSpeechFormat(stereo), (std::vector<std::int16_t>{200, -5, 32767}));
}

TEST(Resample, RatesOutsideTheWavRangeAreRefused) {
  EXPECT_THROW(Resample(std::vector<std::int16_t>(10), 0, 16000), AudioError);
  EXPECT_THROW(Resample(std::vector<std::int16_t>(10), 16000, 1000000), AudioError);
}

}  // namespace
}  // namespace arview::audio
