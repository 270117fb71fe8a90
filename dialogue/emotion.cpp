#include "dialogue/emotion.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arview::dialogue {
namespace {

constexpr std::size_t Index(Emotion emotion) { return static_cast<std::size_t>(emotion); }

// Traits in the order O, C, E, A, N. Each row sums to 1 (docs/dialogue.md, "Emotion", says why
// each emotion leans on the traits it does).
InfluenceMatrix MakeDefaultInfluenceMatrix() {
  InfluenceMatrix p0{};
  auto row = [&p0](Emotion e, double o, double c, double x, double a, double n) {
    p0[Index(e)] = Personality{o, c, x, a, n};
  };
  row(Emotion::kAdmiration, 0.5, 0.0, 0.0, 0.5, 0.0);
  row(Emotion::kAnger, 0.0, 0.0, 0.3, 0.0, 0.7);
  row(Emotion::kDisappointment, 0.0, 0.4, 0.0, 0.0, 0.6);
  row(Emotion::kDisgust, 0.0, 0.4, 0.0, 0.0, 0.6);
  row(Emotion::kDistress, 0.2, 0.0, 0.0, 0.0, 0.8);
  row(Emotion::kFear, 0.0, 0.0, 0.0, 0.0, 1.0);
  row(Emotion::kFearConfirmed, 0.0, 0.2, 0.0, 0.0, 0.8);
  row(Emotion::kGloating, 0.0, 0.0, 0.5, 0.0, 0.5);
  row(Emotion::kGratification, 0.0, 0.5, 0.5, 0.0, 0.0);
  row(Emotion::kGratitude, 0.0, 0.0, 0.3, 0.7, 0.0);
  row(Emotion::kHappyFor, 0.1, 0.0, 0.3, 0.6, 0.0);
  row(Emotion::kHate, 0.0, 0.0, 0.2, 0.0, 0.8);
  row(Emotion::kHope, 0.5, 0.2, 0.3, 0.0, 0.0);
  row(Emotion::kJoy, 0.2, 0.0, 0.5, 0.3, 0.0);
  row(Emotion::kLove, 0.0, 0.0, 0.4, 0.6, 0.0);
  row(Emotion::kPity, 0.0, 0.0, 0.0, 0.8, 0.2);
  row(Emotion::kPride, 0.0, 0.5, 0.5, 0.0, 0.0);
  row(Emotion::kRelief, 0.0, 0.0, 0.0, 0.4, 0.6);
  row(Emotion::kRemorse, 0.0, 0.4, 0.0, 0.3, 0.3);
  row(Emotion::kReproach, 0.0, 0.6, 0.0, 0.0, 0.4);
  row(Emotion::kResentment, 0.0, 0.3, 0.0, 0.0, 0.7);
  row(Emotion::kSatisfaction, 0.2, 0.6, 0.2, 0.0, 0.0);
  row(Emotion::kShame, 0.0, 0.3, 0.0, 0.2, 0.5);
  row(Emotion::kSurprise, 0.7, 0.0, 0.0, 0.0, 0.3);
  return p0;
}

// Angles on the disc in degrees, counter-clockwise from positive evaluation (0°) through high
// activation (90°), to negative evaluation (180°) and low activation (270°).
double DiscAngleDegrees(Emotion emotion) {
  switch (emotion) {
    case Emotion::kGratitude: return 5;
    case Emotion::kGratification: return 10;
    case Emotion::kLove: return 15;
    case Emotion::kAdmiration: return 20;
    case Emotion::kJoy: return 30;
    case Emotion::kHappyFor: return 40;
    case Emotion::kPride: return 45;
    case Emotion::kGloating: return 55;
    case Emotion::kHope: return 60;
    case Emotion::kSurprise: return 80;
    case Emotion::kFear: return 115;
    case Emotion::kAnger: return 130;
    case Emotion::kHate: return 140;
    case Emotion::kDisgust: return 150;
    case Emotion::kReproach: return 160;
    case Emotion::kResentment: return 170;
    case Emotion::kFearConfirmed: return 190;
    case Emotion::kDistress: return 200;
    case Emotion::kDisappointment: return 210;
    case Emotion::kShame: return 220;
    case Emotion::kRemorse: return 225;
    case Emotion::kPity: return 235;
    case Emotion::kRelief: return 325;
    case Emotion::kSatisfaction: return 340;
  }
  return 0;
}

void RequireUnitInterval(double value, const std::string& what) {
  if (!(value >= 0.0 && value <= 1.0)) throw DialogueError("dialogue: " + what + " must be in [0, 1]");
}

}  // namespace

const InfluenceMatrix& DefaultInfluenceMatrix() {
  static const InfluenceMatrix p0 = MakeDefaultInfluenceMatrix();
  return p0;
}

EmotionVector EmotionSensitivity(const InfluenceMatrix& p0, const Personality& personality) {
  EmotionVector u{};
  for (std::size_t i = 0; i < kEmotionCount; ++i)
    for (std::size_t j = 0; j < kTraitCount; ++j) u[i] += p0[i][j] * personality[j];
  return u;
}

EmotionalState::EmotionalState(const Personality& personality, double decay_per_s, const InfluenceMatrix& p0)
    : personality_(personality), decay_per_s_(decay_per_s) {
  for (std::size_t j = 0; j < kTraitCount; ++j)
    RequireUnitInterval(personality[j], "the personality's " + ToString(static_cast<Trait>(j)));
  if (!(decay_per_s >= 0.0) || !std::isfinite(decay_per_s))
    throw DialogueError("dialogue: the decay must be a finite number of at least 0 per second");
  u_ = EmotionSensitivity(p0, personality);
}

void EmotionalState::Update(const EmotionVector& influence, double dt_s) {
  if (!(dt_s >= 0.0) || !std::isfinite(dt_s))
    throw DialogueError("dialogue: an emotion update's time step must be a finite number of at least 0 seconds");
  for (std::size_t i = 0; i < kEmotionCount; ++i)
    RequireUnitInterval(influence[i], "the influence on " + ToString(static_cast<Emotion>(i)));
  for (std::size_t i = 0; i < kEmotionCount; ++i)
    e_[i] = std::clamp(e_[i] + u_[i] * influence[i] - decay_per_s_ * dt_s, 0.0, 1.0);
}

void EmotionalState::Influence(Emotion emotion, double amount) {
  EmotionVector a{};
  a[Index(emotion)] = amount;
  Update(a, 0.0);
}

DiscPoint DiscPosition(Emotion emotion) {
  const double radians = DiscAngleDegrees(emotion) * std::numbers::pi / 180.0;
  return {std::sin(radians), std::cos(radians)};
}

DiscPoint OnDisc(const EmotionVector& intensities) {
  DiscPoint b;
  for (std::size_t i = 0; i < kEmotionCount; ++i) {
    const DiscPoint d = DiscPosition(static_cast<Emotion>(i));
    b.activation += d.activation * intensities[i];
    b.evaluation += d.evaluation * intensities[i];
  }
  const double radius = std::hypot(b.activation, b.evaluation);
  if (radius > 1.0) {
    b.activation /= radius;
    b.evaluation /= radius;
  }
  return b;
}

Expression ExpressionOf(Emotion emotion) {
  switch (emotion) {
    case Emotion::kResentment:
    case Emotion::kPity:
    case Emotion::kDistress:
    case Emotion::kShame:
    case Emotion::kRemorse:
    case Emotion::kDisappointment: return Expression::kSad;
    case Emotion::kAnger:
    case Emotion::kReproach:
    case Emotion::kHate: return Expression::kAngry;
    case Emotion::kSurprise: return Expression::kSurprised;
    case Emotion::kFear:
    case Emotion::kFearConfirmed: return Expression::kAfraid;
    case Emotion::kDisgust: return Expression::kDisgusted;
    default: return Expression::kHappy;  // happy-for, gloating, joy, pride, admiration, love,
                                          // hope, satisfaction, relief, gratification, gratitude
  }
}

EmotionSummary Summarize(const EmotionalState& state) {
  EmotionSummary s;
  const EmotionVector& e = state.Intensities();
  for (std::size_t i = 0; i < kEmotionCount; ++i) {
    if (e[i] > s.intensity) {
      s.intensity = e[i];
      s.dominant = static_cast<Emotion>(i);
    }
  }
  if (s.dominant) {
    s.expression = ExpressionOf(*s.dominant);
    s.expression_intensity = s.intensity;
  }
  s.disc = OnDisc(e);
  s.activation = s.disc.activation;
  return s;
}

double PauseOffsetScale(double activation, double alpha, double beta) {
  return (alpha - activation) * beta;
}

}  // namespace arview::dialogue
