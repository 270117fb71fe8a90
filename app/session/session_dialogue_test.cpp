// The session's dialogue fed by what the viewer does (issue 54): the distance, the side, the gaze
// and a lost camera as the frames give them reach the dialogue's viewer conditions, each reply is
// said by the character's speech, and the dominant emotion shows on the face's morph targets.

#include "app/session/session_dialogue.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <thread>
#include <unistd.h>

#include "app/pipeline/ar_compositor.h"
#include "app/session/test_dialogue_exchange.h"
#include "figure/face_targets.h"
#include "tests/support/sanitizer_slowdown.h"

namespace arview::app {
namespace {

namespace fs = std::filesystem;

// Four machines, each saying its name once when its viewer condition holds; `near` also brings joy.
const char* kViewerDialogue =
    "dialogue: 1\n"
    "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, agreeableness: 0.5, neuroticism: 0.5}\n"
    "decay: 0.01\n"
    "machines:\n"
    "  - {name: looked, states: [a, b], final: [b], transitions: [{from: a, to: b, when: [{viewer_gaze: true}, "
    "{viewer_farther_than: 3}], do: [{say: You are looking at me.}]}]}\n"
    "  - {name: near, states: [a, b], final: [b], transitions: [{from: a, to: b, when: [{viewer_closer_than: 2}], "
    "do: [{say: You came close.}, {emotional_influence: {emotion: joy, value: 1}}]}]}\n"
    "  - {name: behind, states: [a, b], final: [b], transitions: [{from: a, to: b, when: [{viewer_side: behind}], "
    "do: [{say: You are behind me.}]}]}\n"
    "  - {name: lost, states: [a, b], final: [b], transitions: [{from: a, to: b, when: [{viewer_tracked: false}], "
    "do: [{say: Where did you go.}]}]}\n";

// A frame every 10 ms, three times real time: the replies' synthesis (on its own thread) keeps up;
// under a sanitizer, slower (under TSan at 10 ms a frame a reply came over 1 s late, and the
// next one still talked where the face's joy is read).
constexpr std::chrono::milliseconds kPace(static_cast<int>(10 * arview::testing::kSanitizerSlowdown));

struct Step {
  double until_s;
  std::optional<Eigen::Vector3d> eye;  // nothing: the camera lost
  bool looking;                        // the camera's axis on the figure, or straight up
};

TEST(SessionDialogue, TheViewersDistanceSideGazeAndLossReachTheDialogueAndEachReplyIsSaid) {
  const fs::path file = fs::temp_directory_path() / ("arview_viewer_dialogue_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << kViewerDialogue;
  const authoring::AnimatedCharacter character(testing::FigureForDialogue("slt"));
  std::unique_ptr<LayeredAnimator> animator = MakeLayeredAnimator(character);
  std::vector<speech::Utterance> said;
  DialogueSessionOptions o;
  o.dialogue_file = file;
  SessionDialogue session(o, character, *animator, [&](const speech::Utterance& u) { said.push_back(u); }, {});
  EXPECT_TRUE(session.load_notes().empty());

  const std::vector<Step> steps = {
      {1, Eigen::Vector3d(0, 1.6, 5), false},  // far in front, looking away: nothing
      {2, Eigen::Vector3d(0, 1.6, 5), true},   // far, looking at it: looked
      {5, Eigen::Vector3d(0, 1.6, 1.5), true},  // close in front: near
      {8, Eigen::Vector3d(0, 1.6, -1.5), true},  // behind: behind
      {11, std::nullopt, false},                // lost: lost
  };
  const std::string happy_target = figure::ExpressionWeights(figure::Expression::kHappy, 1.0).front().target;
  const int happy = character.character().skeleton.FindMorphTarget(happy_target);
  ASSERT_GE(happy, 0);
  float happy_before_near = -1, happy_after_near = -1;
  double t = 0;
  for (const Step& step : steps) {
    for (; t < step.until_s; t += 1.0 / 30) {
      std::optional<Eigen::Vector3d> axis;
      if (step.eye) axis = step.looking ? (Eigen::Vector3d(0, 1.0, 0) - *step.eye).normalized() : Eigen::Vector3d::UnitY();
      const anim::AnimatorFrame& f = animator->Update(step.eye, t, axis);
      std::this_thread::sleep_for(kPace);
      if (t < 2 && t + 1.0 / 30 >= 2) happy_before_near = f.morph_weights[happy];
      if (t < 4.5 && t + 1.0 / 30 >= 4.5) happy_after_near = f.morph_weights[happy];
    }
  }
  const CharacterDialogue& d = *animator->dialogue();
  ASSERT_EQ(d.turns().size(), 4u);
  const std::vector<std::pair<std::string, double>> expected = {{"looked", 1}, {"near", 2}, {"behind", 5}, {"lost", 8}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(d.turns()[i].machine, expected[i].first);
    EXPECT_NEAR(d.turns()[i].time_s, expected[i].second, 0.05) << expected[i].first;
    EXPECT_GE(d.turns()[i].reply_start_s, d.turns()[i].time_s) << expected[i].first << " was not said";
    EXPECT_TRUE(d.turns()[i].heard.empty());
  }
  ASSERT_EQ(said.size(), 4u);
  EXPECT_EQ(said[1].line->samples.empty(), false);
  EXPECT_TRUE(d.problems().empty());
  // Joy on `near`: the face's happy targets rise (the expression at the emotion's intensity).
  EXPECT_EQ(happy_before_near, 0.0f);
  EXPECT_GT(happy_after_near, 0.1f);
  EXPECT_EQ(d.frame().expression, "happy");
  // The HUD: nothing to listen to here, the machine chosen last, the emotion and the face.
  const std::vector<std::string> hud = DialogueHudLines(d);
  ASSERT_EQ(hud.size(), 2u);
  EXPECT_EQ(hud[0], "heard: not listening");
  EXPECT_EQ(hud[1].rfind("machine: lost   emotion: joy 0.", 0), 0u) << hud[1];
  EXPECT_NE(hud[1].find("face: happy 0."), std::string::npos) << hud[1];
  fs::remove(file);
}

TEST(SessionDialogue, AGestureTheCharacterLacksIsOneNoteAndTheLineIsSaidWithoutIt) {
  const fs::path file = fs::temp_directory_path() / ("arview_gesture_dialogue_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << "dialogue: 1\n"
                         "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, agreeableness: 0.5, "
                         "neuroticism: 0.5}\n"
                         "decay: 0.01\n"
                         "machines:\n"
                         "  - {name: m, states: [a, b], final: [b], transitions: [{from: a, to: b, when: [{viewer_tracked: true}], "
                         "do: [{say: '<gesture name=\"Beckon\"/>Come here.'}, {gesture: Beckon}]}]}\n";
  const authoring::AnimatedCharacter character(testing::FigureForDialogue("slt"));
  std::unique_ptr<LayeredAnimator> animator = MakeLayeredAnimator(character);
  DialogueSessionOptions o;
  o.dialogue_file = file;
  SessionDialogue session(o, character, *animator, {}, {});
  ASSERT_EQ(session.load_notes().size(), 1u);
  EXPECT_NE(session.load_notes()[0].find("has no gesture 'Beckon'"), std::string::npos) << session.load_notes()[0];
  for (double t = 0; t < 2; t += 1.0 / 30) {
    animator->Update(Eigen::Vector3d(0, 1.6, 2), t, std::nullopt);
    std::this_thread::sleep_for(kPace);
  }
  ASSERT_EQ(animator->dialogue()->turns().size(), 1u);
  EXPECT_GE(animator->dialogue()->turns()[0].reply_start_s, 0);
  EXPECT_TRUE(animator->dialogue()->problems().empty());
  fs::remove(file);
}

}  // namespace
}  // namespace arview::app
