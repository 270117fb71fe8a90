#pragma once
// Personality and emotion (Egges' thesis §5.2): an OCEAN personality p (five traits in [0,1]), an
// emotional state e of 24 intensities in [0,1] (OCC's 22, surprise and disgust: Table 5.1), and
// the linear update of Eq. 5.7-5.11 with the decay per second of frame time:
//
//   u = P0·p,  P = diag(u),  e' = clamp(e + P·a − C_e·dt, 0, 1)
//
// where a is an emotional influence (each δ_i in [0,1], Eq. 5.6). The state maps onto the
// activation-evaluation disc as b = D·e (Eq. 5.15), kept inside the unit disc (Eq. 4.1), and onto
// the face as one of Ekman's six expressions (Table 5.2) scaled by the dominant emotion's
// intensity. P0 and D are ours: the thesis gives neither (docs/dialogue.md, "Emotion").

#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include "base/enum_table.h"
#include "base/error.h"

namespace arview::dialogue {

class DialogueError : public Error {
 public:
  using Error::Error;
};

enum class Trait { kOpenness, kConscientiousness, kExtraversion, kAgreeableness, kNeuroticism };
inline constexpr std::size_t kTraitCount = 5;
constexpr auto EnumNames(Trait) {
  return EnumTable<Trait, kTraitCount>{{{Trait::kOpenness, "openness"},
                                        {Trait::kConscientiousness, "conscientiousness"},
                                        {Trait::kExtraversion, "extraversion"},
                                        {Trait::kAgreeableness, "agreeableness"},
                                        {Trait::kNeuroticism, "neuroticism"}}};
}

// Table 5.1, alphabetical as there; names as dialogue files spell them.
enum class Emotion {
  kAdmiration, kAnger, kDisappointment, kDisgust, kDistress, kFear, kFearConfirmed, kGloating,
  kGratification, kGratitude, kHappyFor, kHate, kHope, kJoy, kLove, kPity, kPride, kRelief,
  kRemorse, kReproach, kResentment, kSatisfaction, kShame, kSurprise
};
inline constexpr std::size_t kEmotionCount = 24;
constexpr auto EnumNames(Emotion) {
  return EnumTable<Emotion, kEmotionCount>{{
      {Emotion::kAdmiration, "admiration"}, {Emotion::kAnger, "anger"},
      {Emotion::kDisappointment, "disappointment"}, {Emotion::kDisgust, "disgust"},
      {Emotion::kDistress, "distress"}, {Emotion::kFear, "fear"},
      {Emotion::kFearConfirmed, "fear_confirmed"}, {Emotion::kGloating, "gloating"},
      {Emotion::kGratification, "gratification"}, {Emotion::kGratitude, "gratitude"},
      {Emotion::kHappyFor, "happy_for"}, {Emotion::kHate, "hate"}, {Emotion::kHope, "hope"},
      {Emotion::kJoy, "joy"}, {Emotion::kLove, "love"}, {Emotion::kPity, "pity"},
      {Emotion::kPride, "pride"}, {Emotion::kRelief, "relief"}, {Emotion::kRemorse, "remorse"},
      {Emotion::kReproach, "reproach"}, {Emotion::kResentment, "resentment"},
      {Emotion::kSatisfaction, "satisfaction"}, {Emotion::kShame, "shame"},
      {Emotion::kSurprise, "surprise"}}};
}

using Personality = std::array<double, kTraitCount>;    // indexed by Trait
using EmotionVector = std::array<double, kEmotionCount>;  // indexed by Emotion
// P0 (Eq. 5.8): row i says how much each trait lets emotion i rise.
using InfluenceMatrix = std::array<Personality, kEmotionCount>;

// The default P0 (the table in docs/dialogue.md): each row's weights are non-negative and sum
// to 1, so that a personality of 0.5 everywhere gives every emotion the sensitivity 0.5.
const InfluenceMatrix& DefaultInfluenceMatrix();

// u = P0·p (Eq. 5.8): the diagonal of P.
EmotionVector EmotionSensitivity(const InfluenceMatrix& p0, const Personality& personality);

// The state of an individual (p, e_t): e_0 = 0 (Eq. 5.3).
class EmotionalState {
 public:
  // Throws DialogueError when a trait is outside [0,1] or the decay is negative or not finite.
  EmotionalState(const Personality& personality, double decay_per_s,
                 const InfluenceMatrix& p0 = DefaultInfluenceMatrix());

  // e' = clamp(e + P·a − C_e·dt, 0, 1). Each influence in [0,1] and dt >= 0 (a DialogueError
  // otherwise: the callers check their inputs first).
  void Update(const EmotionVector& influence, double dt_s);
  // One emotion's influence (an action's), no time passing.
  void Influence(Emotion emotion, double amount);
  // Time passing with no influence: the decay alone.
  void Decay(double dt_s) { Update(EmotionVector{}, dt_s); }

  double Intensity(Emotion emotion) const { return e_[static_cast<std::size_t>(emotion)]; }
  const EmotionVector& Intensities() const { return e_; }
  const EmotionVector& Sensitivity() const { return u_; }
  const Personality& personality() const { return personality_; }

 private:
  Personality personality_{};
  EmotionVector u_{};
  EmotionVector e_{};
  double decay_per_s_ = 0;
};

// A point of the activation-evaluation disc: both in [-1,1], sqrt(a² + e²) <= 1 (Eq. 4.1).
struct DiscPoint {
  double activation = 0;
  double evaluation = 0;
};

// D's column for an emotion (Eq. 5.14): where it sits on the disc (unit length; our reading of
// the thesis's Fig. 5.6, whose coordinates the text does not give: docs/dialogue.md).
DiscPoint DiscPosition(Emotion emotion);

// b = D·e (Eq. 5.15), scaled back onto the unit disc when the sum leaves it.
DiscPoint OnDisc(const EmotionVector& intensities);

// Ekman's six, named as the figure's expressions (figure/face_targets.h ExpressionName).
enum class Expression { kHappy, kSad, kAngry, kSurprised, kAfraid, kDisgusted };
constexpr auto EnumNames(Expression) {
  return EnumTable<Expression, 6>{{{Expression::kHappy, "happy"},
                                   {Expression::kSad, "sad"},
                                   {Expression::kAngry, "angry"},
                                   {Expression::kSurprised, "surprised"},
                                   {Expression::kAfraid, "afraid"},
                                   {Expression::kDisgusted, "disgusted"}}};
}

// Table 5.2: the expression an emotion shows.
Expression ExpressionOf(Emotion emotion);

// What the rest of the system reads of the emotional state.
struct EmotionSummary {
  std::optional<Emotion> dominant;  // the most intense emotion; none while every one is 0
  double intensity = 0;             // the dominant emotion's
  std::optional<Expression> expression;  // ExpressionOf(dominant); none when neutral
  double expression_intensity = 0;       // = intensity: the face's scaling factor (§5.3.1)
  DiscPoint disc;                   // OnDisc(e)
  double activation = 0;            // disc.activation: drives the idle pace (thesis §4.1.2)
};
// Ties go to the emotion listed first in Table 5.1's order (the enum's).
EmotionSummary Summarize(const EmotionalState& state);

// The idle pause's random offset scale (thesis Eq. 4.2): p_o' = (alpha − activation)·beta·p_o;
// the thesis's defaults alpha = 1, beta = 1 give 0 at full activation and 2 at the calmest.
double PauseOffsetScale(double activation, double alpha = 1.0, double beta = 1.0);

}  // namespace arview::dialogue
