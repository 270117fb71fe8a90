#include "listen/voicing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "listen/test_listen_data.h"

namespace arview::listen {
namespace {

// A tone whose frequency moves as `hz(t)`, at `peak` of full scale.
std::vector<std::int16_t> Tone(double seconds, const std::function<double(double)>& hz, double peak) {
  std::vector<std::int16_t> samples(static_cast<std::size_t>(seconds * 16000));
  double phase = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double t = static_cast<double>(i) / 16000;
    phase += 2 * M_PI * hz(t) / 16000;
    // A glottal-like pulse train rather than a sine: the fundamental and four harmonics.
    double wave = 0;
    for (int h = 1; h <= 5; ++h) wave += std::sin(h * phase) / h;
    samples[i] = testing::Clip(peak * 32767 * wave / 2.3);
  }
  return samples;
}

TEST(Voicing, AHeldNoteIsVoicedWithAPitchThatDoesNotMove) {
  const Voicing voicing = MeasureVoicing(Tone(1.0, [](double) { return 200.0; }, 0.3));
  EXPECT_GT(voicing.voiced_fraction, 0.95);
  EXPECT_GT(voicing.longest_steady_pitch_s, 0.9);
}

TEST(Voicing, AGlidingPitchIsVoicedButNeverSteady) {
  // 120 to 180 Hz over a second, as a voice's intonation moves: the period changes by more
  // than a sample every 20 ms or so.
  const Voicing voicing = MeasureVoicing(Tone(1.0, [](double t) { return 120.0 + 60.0 * t; }, 0.3));
  EXPECT_GT(voicing.voiced_fraction, 0.95);
  EXPECT_LT(voicing.longest_steady_pitch_s, 0.12);
}

TEST(Voicing, NoiseAndSilenceHaveNoPitch) {
  EXPECT_EQ(MeasureVoicing(testing::WhiteNoise(16000, 3000, 1)).voiced_fraction, 0.0);
  EXPECT_LT(MeasureVoicing(testing::PinkNoise(16000, 3000, 2)).voiced_fraction, 0.05);
  EXPECT_EQ(MeasureVoicing(testing::Silence(16000)).voiced_fraction, 0.0);
  // A held note too quiet to be a voice at the microphone (under 1% of full scale).
  EXPECT_EQ(MeasureVoicing(Tone(1.0, [](double) { return 200.0; }, 0.005)).voiced_fraction, 0.0);
}

TEST(Voicing, LessThanOneFrameMeasuresNothing) {
  const Voicing voicing = MeasureVoicing(Tone(0.03, [](double) { return 200.0; }, 0.3));
  EXPECT_EQ(voicing.voiced_fraction, 0.0);
  EXPECT_EQ(voicing.longest_steady_pitch_s, 0.0);
}

}  // namespace
}  // namespace arview::listen
