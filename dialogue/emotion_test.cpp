#include "dialogue/emotion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace arview::dialogue {
namespace {

// The thesis's example personality (Eq. 5.2): very open, not conscientious, extravert, quite
// agreeable, hardly neurotic.
const Personality kThesisPersonality{0.8, 0.1, 0.7, 0.5, 0.05};

EmotionVector Only(Emotion emotion, double value, EmotionVector a = {}) {
  a[static_cast<std::size_t>(emotion)] = value;
  return a;
}

TEST(EmotionUpdate, FollowsAHandComputedSequence) {
  // u_joy = 0.2·0.8 + 0.5·0.7 + 0.3·0.5 = 0.66; u_fear = 1.0·0.05 = 0.05 (the default P0's rows).
  EmotionalState state(kThesisPersonality, /*decay_per_s=*/0.1);
  EXPECT_NEAR(state.Sensitivity()[static_cast<std::size_t>(Emotion::kJoy)], 0.66, 1e-12);
  EXPECT_NEAR(state.Sensitivity()[static_cast<std::size_t>(Emotion::kFear)], 0.05, 1e-12);
  EXPECT_EQ(state.Intensity(Emotion::kJoy), 0.0);  // e_0 = 0 (Eq. 5.3)

  state.Update(Only(Emotion::kJoy, 0.5), 0.5);  // 0 + 0.66·0.5 − 0.1·0.5 = 0.28; fear 0 − 0.05 → 0
  EXPECT_NEAR(state.Intensity(Emotion::kJoy), 0.28, 1e-12);
  EXPECT_EQ(state.Intensity(Emotion::kFear), 0.0);

  state.Update(Only(Emotion::kFear, 1.0, Only(Emotion::kJoy, 1.0)), 1.0);  // 0.28 + 0.66 − 0.1; 0 + 0.05 − 0.1 → 0
  EXPECT_NEAR(state.Intensity(Emotion::kJoy), 0.84, 1e-12);
  EXPECT_EQ(state.Intensity(Emotion::kFear), 0.0);

  state.Influence(Emotion::kFear, 1.0);  // 0 + 0.05, no time
  EXPECT_NEAR(state.Intensity(Emotion::kFear), 0.05, 1e-12);

  state.Influence(Emotion::kJoy, 1.0);  // 0.84 + 0.66 = 1.5 → 1
  EXPECT_EQ(state.Intensity(Emotion::kJoy), 1.0);

  state.Decay(2.0);  // 1 − 0.2; fear 0.05 − 0.2 → 0
  EXPECT_NEAR(state.Intensity(Emotion::kJoy), 0.8, 1e-12);
  EXPECT_EQ(state.Intensity(Emotion::kFear), 0.0);
  for (std::size_t i = 0; i < kEmotionCount; ++i) {
    if (i != static_cast<std::size_t>(Emotion::kJoy)) {
      EXPECT_EQ(state.Intensities()[i], 0.0) << ToString(static_cast<Emotion>(i));
    }
  }
}

TEST(EmotionUpdate, TheSamePraiseMovesAnExtravertMoreThanAnIntrovert) {
  EmotionalState extravert({0.5, 0.5, 1.0, 0.8, 0.1}, 0.0);
  EmotionalState introvert({0.5, 0.5, 0.0, 0.2, 0.9}, 0.0);
  extravert.Influence(Emotion::kJoy, 0.5);
  introvert.Influence(Emotion::kJoy, 0.5);
  EXPECT_GT(extravert.Intensity(Emotion::kJoy), 2 * introvert.Intensity(Emotion::kJoy));
  extravert.Influence(Emotion::kFear, 0.5);
  introvert.Influence(Emotion::kFear, 0.5);
  EXPECT_LT(extravert.Intensity(Emotion::kFear), introvert.Intensity(Emotion::kFear));
}

TEST(EmotionUpdate, EveryRowOfTheDefaultMatrixSumsToOne) {
  const EmotionVector u = EmotionSensitivity(DefaultInfluenceMatrix(), {0.5, 0.5, 0.5, 0.5, 0.5});
  for (std::size_t i = 0; i < kEmotionCount; ++i) {
    EXPECT_NEAR(u[i], 0.5, 1e-12) << ToString(static_cast<Emotion>(i));
    for (const double w : DefaultInfluenceMatrix()[i]) EXPECT_GE(w, 0.0);
  }
}

TEST(EmotionUpdate, RefusesTraitsInfluencesAndStepsOutOfRange) {
  try {
    EmotionalState({0.5, 0.5, 1.5, 0.5, 0.5}, 0.1);
    FAIL() << "accepted extraversion 1.5";
  } catch (const DialogueError& e) {
    EXPECT_NE(std::string(e.what()).find("extraversion"), std::string::npos) << e.what();
  }
  EXPECT_THROW(EmotionalState({0.5, 0.5, 0.5, 0.5, 0.5}, -1.0), DialogueError);
  EXPECT_THROW(EmotionalState({0.5, 0.5, 0.5, 0.5, 0.5}, std::nan("")), DialogueError);
  EmotionalState state({0.5, 0.5, 0.5, 0.5, 0.5}, 0.1);
  EXPECT_THROW(state.Influence(Emotion::kHate, 1.2), DialogueError);
  EXPECT_THROW(state.Influence(Emotion::kHate, -0.1), DialogueError);
  EXPECT_THROW(state.Decay(-1.0), DialogueError);
  EXPECT_THROW(state.Decay(std::nan("")), DialogueError);
}

TEST(EmotionDisc, EveryEmotionSitsOnTheRimWherePsychologyPutsIt) {
  for (std::size_t i = 0; i < kEmotionCount; ++i) {
    const DiscPoint d = DiscPosition(static_cast<Emotion>(i));
    EXPECT_NEAR(std::hypot(d.activation, d.evaluation), 1.0, 1e-12);
  }
  EXPECT_GT(DiscPosition(Emotion::kJoy).evaluation, 0.5);
  EXPECT_GT(DiscPosition(Emotion::kJoy).activation, 0.0);
  EXPECT_LT(DiscPosition(Emotion::kFear).evaluation, 0.0);
  EXPECT_GT(DiscPosition(Emotion::kFear).activation, 0.5);
  EXPECT_LT(DiscPosition(Emotion::kDistress).activation, 0.0);
  EXPECT_LT(DiscPosition(Emotion::kRelief).activation, 0.0);
  EXPECT_GT(DiscPosition(Emotion::kRelief).evaluation, 0.0);
}

TEST(EmotionDisc, TheSumOfManyEmotionsStaysInsideTheDisc) {
  EmotionVector all{};
  all.fill(1.0);
  all[static_cast<std::size_t>(Emotion::kJoy)] = 1.0;
  EmotionVector positive{};
  for (const Emotion e : {Emotion::kJoy, Emotion::kHope, Emotion::kPride, Emotion::kLove}) positive[static_cast<std::size_t>(e)] = 1.0;
  for (const EmotionVector& e : {all, positive}) {
    const DiscPoint b = OnDisc(e);
    EXPECT_LE(std::hypot(b.activation, b.evaluation), 1.0 + 1e-12);
  }
  const DiscPoint half_joy = OnDisc(Only(Emotion::kJoy, 0.5));
  EXPECT_NEAR(half_joy.evaluation, 0.5 * DiscPosition(Emotion::kJoy).evaluation, 1e-12);  // b = D·e inside the disc
}

TEST(EmotionFace, TheDominantEmotionPicksTheThesisExpression) {
  std::map<Expression, int> emotions_per_expression;
  for (std::size_t i = 0; i < kEmotionCount; ++i) ++emotions_per_expression[ExpressionOf(static_cast<Emotion>(i))];
  EXPECT_EQ(emotions_per_expression[Expression::kHappy], 11);  // Table 5.2's rows
  EXPECT_EQ(emotions_per_expression[Expression::kSad], 6);
  EXPECT_EQ(emotions_per_expression[Expression::kAngry], 3);
  EXPECT_EQ(emotions_per_expression[Expression::kSurprised], 1);
  EXPECT_EQ(emotions_per_expression[Expression::kAfraid], 2);
  EXPECT_EQ(emotions_per_expression[Expression::kDisgusted], 1);

  EmotionalState state({0.5, 0.5, 0.5, 0.5, 0.5}, 0.0);
  EmotionSummary neutral = Summarize(state);
  EXPECT_FALSE(neutral.dominant);
  EXPECT_FALSE(neutral.expression);
  EXPECT_EQ(neutral.activation, 0.0);

  state.Influence(Emotion::kJoy, 0.4);       // 0.2
  state.Influence(Emotion::kReproach, 0.8);  // 0.4
  const EmotionSummary s = Summarize(state);
  ASSERT_TRUE(s.dominant);
  EXPECT_EQ(*s.dominant, Emotion::kReproach);
  EXPECT_EQ(*s.expression, Expression::kAngry);
  EXPECT_NEAR(s.expression_intensity, 0.4, 1e-12);
  EXPECT_EQ(ToString(*s.expression), "angry");  // the figure's ExpressionName
}

TEST(EmotionIdle, HigherActivationShortensThePauses) {
  EXPECT_DOUBLE_EQ(PauseOffsetScale(1.0), 0.0);
  EXPECT_DOUBLE_EQ(PauseOffsetScale(0.0), 1.0);
  EXPECT_DOUBLE_EQ(PauseOffsetScale(-1.0), 2.0);
  EmotionalState state({0.5, 0.5, 0.5, 0.5, 0.5}, 0.0);
  state.Influence(Emotion::kAnger, 1.0);
  const double angry = Summarize(state).activation;
  EmotionalState calm({0.5, 0.5, 0.5, 0.5, 0.5}, 0.0);
  calm.Influence(Emotion::kRelief, 1.0);
  EXPECT_GT(angry, 0.0);
  EXPECT_LT(Summarize(calm).activation, 0.0);
  EXPECT_LT(PauseOffsetScale(angry), PauseOffsetScale(Summarize(calm).activation));
}

}  // namespace
}  // namespace arview::dialogue
