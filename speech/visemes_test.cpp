#include "speech/visemes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <set>
#include <string>

namespace {
// Counts every allocation of the test binary, to show that sampling makes none.
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace arview::speech {
namespace {

using ::testing::HasSubstr;

constexpr double kVideoFrame = 1.0 / 30.0;

TEST(Dominance, IsOneAtTheCentreAndZeroAtTheEnds) {
  for (const double alpha : {1.0, 3.0}) {
    EXPECT_DOUBLE_EQ(Dominance(alpha, 0.5), 1.0);
    EXPECT_NEAR(Dominance(alpha, 0.0), 0.0, 1e-12);
    EXPECT_NEAR(Dominance(alpha, 1.0), 0.0, 1e-12);
    EXPECT_EQ(Dominance(alpha, -0.1), 0.0);
    EXPECT_EQ(Dominance(alpha, 1.1), 0.0);
    EXPECT_DOUBLE_EQ(Dominance(alpha, 0.3), Dominance(alpha, 0.7));
  }
  // The thesis's formula at x = 0.25, α = 3: e^(−1.5) − 0.5·e^(−3).
  EXPECT_NEAR(Dominance(3.0, 0.25), std::exp(-1.5) - 0.5 * std::exp(-3.0), 1e-12);
  // Sharper with α: the lips' curve falls faster.
  EXPECT_LT(Dominance(3.0, 0.3), Dominance(1.0, 0.3));
}

TEST(PhoneVisemeTable, CoversFlitesPhoneSetAndEveryViseme) {
  const char* const cmu[] = {"aa", "ae", "ah", "ao", "aw", "ay", "b",  "ch", "d",  "dh", "eh", "er", "ey",
                             "f",  "g",  "hh", "ih", "iy", "jh", "k",  "l",  "m",  "n",  "ng", "ow", "oy",
                             "p",  "r",  "s",  "sh", "t",  "th", "uh", "uw", "v",  "w",  "y",  "z",  "zh", "pau"};
  for (const char* phone : cmu) EXPECT_NO_THROW((void)PhoneVisemeRowOf(phone)) << phone;
  std::set<Viseme> used;
  for (const PhoneVisemeRow& row : PhoneVisemeTable()) used.insert(row.viseme);
  EXPECT_EQ(used.size(), kVisemeCount);
  EXPECT_EQ(PhoneVisemeRowOf("m").viseme, Viseme::kPP);
  EXPECT_EQ(PhoneVisemeRowOf("m").shape.weight, 1.5);
  EXPECT_EQ(PhoneVisemeRowOf("f").viseme, Viseme::kFF);
  EXPECT_EQ(PhoneVisemeRowOf("pau").shape.spread, 2.0);
  EXPECT_EQ(PhoneVisemeRowOf("aa").shape.spread, 5.0);
  EXPECT_EQ(PhoneVisemeRowOf("k").shape.spread, 3.0);
}

TEST(PhoneVisemeTable, AnUnknownPhoneIsAnErrorNamingIt) {
  try {
    (void)PhoneVisemeRowOf("qx");
    FAIL() << "no error";
  } catch (const SpeechError& error) {
    EXPECT_THAT(error.what(), HasSubstr("'qx'"));
  }
  const Phone phones[] = {{"pau", 0, 0.1}, {"qx", 0.1, 0.2}};
  EXPECT_THROW(VisemeTrack{phones}, SpeechError);
}

TEST(VisemeTrack, WeightsSumToOneAndAreSilenceOutsideTheLine) {
  const Phone phones[] = {{"pau", 0.0, 0.2}, {"hh", 0.2, 0.25}, {"ax", 0.25, 0.3}, {"l", 0.3, 0.38},
                          {"ow", 0.38, 0.55}, {"pau", 0.55, 0.7}};
  const VisemeTrack track(phones);
  VisemeWeights weights;
  for (double t = -0.5; t < 1.5; t += 0.01) {
    track.Sample(t, weights);
    float sum = 0;
    for (const float w : weights) {
      EXPECT_GE(w, 0.0f);
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0f, 1e-5f) << t;
  }
  track.Sample(-0.5, weights);
  EXPECT_EQ(weights[static_cast<std::size_t>(Viseme::kSil)], 1.0f);
  track.Sample(1.5, weights);
  EXPECT_EQ(weights[static_cast<std::size_t>(Viseme::kSil)], 1.0f);
  track.Sample(0.465, weights);  // the centre of "ow"
  EXPECT_GT(weights[static_cast<std::size_t>(Viseme::kOh)], 0.5f);
}

TEST(VisemeTrack, SamplingAllocatesNothing) {
  const SpokenLine line = Synthesizer(Voice::kSlt).Synthesize("Sampling the mouth costs no memory.");
  const VisemeTrack track(line.phones);
  VisemeWeights weights;
  const long before = allocations.load();
  for (double t = 0; t < line.DurationSeconds(); t += 0.001) track.Sample(t, weights);
  EXPECT_EQ(allocations.load(), before);
}

TEST(VisemeTrack, TheSameLineGivesTheSameCurves) {
  const Synthesizer synthesizer(Voice::kRms);
  const std::string text = "Please bring me my pen.";
  const VisemeTrack first(synthesizer.Synthesize(text).phones);
  const VisemeTrack second(synthesizer.Synthesize(text).phones);
  VisemeWeights a, b;
  for (double t = 0; t < 2.0; t += 0.005) {
    first.Sample(t, a);
    second.Sample(t, b);
    EXPECT_EQ(a, b) << t;
  }
}

bool IsBilabial(const std::string& phone) { return phone == "p" || phone == "b" || phone == "m"; }

// The lips close: the PP viseme peaks within one video frame of every p, b and m's centre (the
// local maximum that climbing from the centre reaches lies within a frame of it: two bilabials
// in a row, "number", keep the lips shut across both, with a peak at each) and is the largest
// of the 15 weights there.
double NearestPeak(const VisemeTrack& track, double centre) {
  VisemeWeights weights;
  const auto pp_at = [&](double t) {
    track.Sample(t, weights);
    return weights[static_cast<std::size_t>(Viseme::kPP)];
  };
  constexpr double kStep = 0.0005;
  const double step = pp_at(centre + kStep) >= pp_at(centre - kStep) ? kStep : -kStep;
  double t = centre;
  while (pp_at(t + step) > pp_at(t) && std::abs(t - centre) < 1.0) t += step;
  return t;
}

TEST(VisemeTrack, PPPeaksAtEveryBilabialsCentreAndDominatesThere) {
  const char* const sentences[] = {
      "Maybe the big brown map belongs to Bob.",
      "Please pass me the apple pie, Pam.",
      "My mother bought a basket of plums in Bombay.",
      "Remember to bring them back by the fourth of September.",
      "The number of people in the museum is improbable.",
      "Hello, I am the figure in your room; come and be my guest.",
  };
  int checked = 0;
  for (const Voice voice : {Voice::kSlt, Voice::kRms, Voice::kAwb}) {
    const Synthesizer synthesizer(voice);
    for (const char* sentence : sentences) {
      const SpokenLine line = synthesizer.Synthesize(sentence);
      const VisemeTrack track(line.phones);
      VisemeWeights weights;
      for (const Phone& phone : line.phones) {
        if (!IsBilabial(phone.name)) continue;
        const double centre = 0.5 * (phone.start_s + phone.end_s);
        const double peak_time = NearestPeak(track, centre);
        const std::string where = ToString(voice) + ": \"" + sentence + "\" " + phone.name + " at " +
                                  std::to_string(centre) + " s";
        EXPECT_LE(std::abs(peak_time - centre), kVideoFrame) << where;
        track.Sample(centre, weights);
        const float pp = weights[static_cast<std::size_t>(Viseme::kPP)];
        for (std::size_t v = 0; v < kVisemeCount; ++v) {
          if (v != static_cast<std::size_t>(Viseme::kPP)) {
            EXPECT_GT(pp, weights[v]) << where << " against " << ToString(static_cast<Viseme>(v));
          }
        }
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 60);
}

}  // namespace
}  // namespace arview::speech
