#include "dialogue/dialogue.h"

#include <gtest/gtest.h>

#include <set>

#include "dialogue/test_dialogues.h"

namespace arview::dialogue {
namespace {

using testing::Header;

DialogueManager Manager(const std::string& machines, std::uint64_t seed = 0, const std::string& variables = "") {
  return DialogueManager(ParseDialogue(Header(variables) + machines, "d.yaml"), seed);
}

DialogueInput Heard(const std::string& text, double dt = 1.0) {
  DialogueInput input;
  input.dt_s = dt;
  input.heard = text;
  input.viewer = {true, 1.0, true, true};
  return input;
}

// A machine that answers `pattern` with `reply` in every state it is in (cyclic, one final state).
std::string Answerer(const std::string& name, int priority, const std::string& pattern, const std::string& reply) {
  return "  - name: " + name + "\n    priority: " + std::to_string(priority) +
         "\n    cyclic: true\n    states: [listening, answered]\n    final: [answered]\n    transitions:\n"
         "      - from: listening\n        to: answered\n        when:\n          - heard: \"" +
         pattern + "\"\n        do:\n          - say: " + reply + "\n";
}

// play → asked; then "yes" → done. Strong or not.
std::string Game(bool strong) {
  return std::string("  - name: game\n    priority: 0\n    strong: ") + (strong ? "true" : "false") +
         "\n    states: [idle, asked, done]\n    final: [done]\n    transitions:\n"
         "      - from: idle\n        to: asked\n        when:\n          - heard: play\n        do:\n          - say: Ready?\n"
         "      - from: asked\n        to: done\n        when:\n          - heard: yes\n        do:\n          - say: Go!\n";
}

std::string Said(const DialogueTurn& turn) {
  std::string said;
  for (const DialogueStep& step : turn.steps)
    for (const std::string& line : step.said) said += (said.empty() ? "" : " | ") + step.machine + ": " + line;
  return said;
}

TEST(DialogueManager, TheHighestPriorityMachineThatCanAnswerAnswers) {
  DialogueManager m = Manager(Answerer("low", 0, "*", "low") + Answerer("high", 5, "hello *", "high"));
  EXPECT_EQ(Said(m.Update(Heard("hello there"))), "high: high");
  EXPECT_EQ(Said(m.Update(Heard("something else"))), "low: low");  // high cannot: low takes it
  EXPECT_EQ(m.SelectedMachine(), "low");
}

TEST(DialogueManager, AStrongMachineKeepsTheConversationWhileItCanMakeATransition) {
  DialogueManager strong = Manager(Game(true) + Answerer("yes_man", 5, "yes", "Yes yourself."));
  EXPECT_EQ(Said(strong.Update(Heard("play"))), "game: Ready?");
  EXPECT_EQ(Said(strong.Update(Heard("yes"))), "game: Go!");  // over the priority 5 answerer
  EXPECT_TRUE(strong.Finished("game"));
  EXPECT_EQ(Said(strong.Update(Heard("yes"))), "yes_man: Yes yourself.");  // released once finished

  DialogueManager weak = Manager(Game(false) + Answerer("yes_man", 5, "yes", "Yes yourself."));
  weak.Update(Heard("play"));
  EXPECT_EQ(Said(weak.Update(Heard("yes"))), "yes_man: Yes yourself.");
  EXPECT_EQ(weak.StateOf("game"), "asked");
}

TEST(DialogueManager, AStrongMachineThatCannotAnswerLetsTheOthersAnswer) {
  DialogueManager m = Manager(Game(true) + Answerer("chat", 0, "how are you", "Fine."));
  m.Update(Heard("play"));
  EXPECT_EQ(Said(m.Update(Heard("how are you"))), "chat: Fine.");
  EXPECT_EQ(m.StateOf("game"), "asked");
  EXPECT_EQ(Said(m.Update(Heard("yes"))), "game: Go!");
}

TEST(DialogueManager, MachinesOfEqualPriorityAreChosenAtRandomButRepeatablyForASeed) {
  const std::string machines = Answerer("a", 1, "*", "a") + Answerer("b", 1, "*", "b");
  std::set<std::string> chosen;
  for (std::uint64_t seed = 0; seed < 16; ++seed) {
    DialogueManager first = Manager(machines, seed);
    DialogueManager again = Manager(machines, seed);
    const std::string said = Said(first.Update(Heard("hi")));
    EXPECT_EQ(said, Said(again.Update(Heard("hi"))));
    chosen.insert(said);
  }
  EXPECT_EQ(chosen.size(), 2u);
}

TEST(DialogueManager, TheHeardTextIsTakenOnceAndLambdaTransitionsFollowInTheSameUpdate) {
  // q0 →(heard)→ q1 →(λ: say)→ q2: the thesis's Fig. 5.1.
  DialogueManager m = Manager(
      "  - name: fsm\n    states: [q0, q1, q2]\n    final: [q2]\n    transitions:\n"
      "      - from: q0\n        to: q1\n        when:\n          - heard: \"hello my name is *\"\n"
      "        do:\n          - set: {name: name, value: $1}\n"
      "      - from: q1\n        to: q2\n        do:\n          - say: hello ${name} how are you doing?\n" +
          Answerer("other", 0, "*", "other"),
      0, "name: ''");
  const DialogueTurn turn = m.Update(Heard("Hello, my name is Ann"));
  EXPECT_TRUE(turn.heard_taken);
  ASSERT_EQ(turn.steps.size(), 2u);
  EXPECT_TRUE(turn.steps[0].took_heard);
  EXPECT_FALSE(turn.steps[1].took_heard);
  EXPECT_EQ(Said(turn), "fsm: hello ann how are you doing?");  // `other` never heard it
  EXPECT_EQ(m.Variable("name"), "ann");
  EXPECT_TRUE(m.Finished("fsm"));
}

TEST(DialogueManager, CyclicMachinesRestartAndFinishedOnesStopListening) {
  DialogueManager m = Manager(Answerer("again", 0, "ping", "pong") + Game(false));
  EXPECT_EQ(m.ExpectedPhrases(), (std::vector<std::string>{"ping", "play"}));
  EXPECT_EQ(Said(m.Update(Heard("ping"))), "again: pong");
  EXPECT_EQ(m.StateOf("again"), "listening");
  EXPECT_EQ(Said(m.Update(Heard("ping"))), "again: pong");
  m.Update(Heard("play"));
  EXPECT_EQ(m.ExpectedPhrases(), (std::vector<std::string>{"ping", "yes"}));
  m.Update(Heard("yes"));
  EXPECT_EQ(m.ExpectedPhrases(), (std::vector<std::string>{"ping"}));
}

TEST(DialogueManager, TimeInAStateAndTheViewerAreConditionsToo) {
  DialogueManager m = Manager(
      "  - name: viewer\n    states: [far, near, behind, gone]\n    transitions:\n"
      "      - from: far\n        to: near\n        when:\n          - viewer_closer_than: 2\n          - viewer_gaze: true\n"
      "        do:\n          - say: hello\n"
      "      - from: near\n        to: behind\n        when:\n          - viewer_side: behind\n          - in_state_longer_than: 3\n"
      "        do:\n          - say: behind me?\n"
      "      - from: behind\n        to: gone\n        when:\n          - viewer_tracked: false\n        do:\n          - say: where are you?\n");
  DialogueInput in;
  in.dt_s = 1;
  in.viewer = {true, 3.0, true, true};
  EXPECT_EQ(Said(m.Update(in)), "");
  in.viewer.distance_m = 1.5;
  in.viewer.gaze_on_character = false;
  EXPECT_EQ(Said(m.Update(in)), "");
  in.viewer.gaze_on_character = true;
  EXPECT_EQ(Said(m.Update(in)), "viewer: hello");
  in.viewer.in_front = false;
  EXPECT_EQ(Said(m.Update(in)), "");  // 1 s behind
  EXPECT_EQ(Said(m.Update(in)), "");  // 2 s
  EXPECT_EQ(Said(m.Update(in)), "");  // 3 s: not longer than 3
  EXPECT_EQ(Said(m.Update(in)), "viewer: behind me?");
  in.viewer = {false, 0.5, true, true};  // lost: distance, side and gaze are unknown
  EXPECT_EQ(Said(m.Update(in)), "viewer: where are you?");
}

TEST(DialogueManager, UntrackedViewerSatisfiesNoDistanceSideOrGazeCondition) {
  DialogueManager m = Manager(
      "  - name: v\n    states: [a, b]\n    transitions:\n"
      "      - from: a\n        to: b\n        when:\n          - viewer_closer_than: 100\n"
      "      - from: a\n        to: b\n        when:\n          - viewer_side: front\n"
      "      - from: a\n        to: b\n        when:\n          - viewer_gaze: false\n");
  DialogueInput in;
  in.viewer = {false, 1.0, true, false};
  EXPECT_TRUE(m.Update(in).steps.empty());
}

TEST(DialogueManager, EmotionsTheDialogueSendsAndThresholdsItReads) {
  DialogueManager feel = Manager(
      "  - name: praise\n    cyclic: true\n    states: [l, a]\n    final: [a]\n    transitions:\n"
      "      - from: l\n        to: a\n        when:\n          - heard: \"you are *\"\n"
      "        do:\n          - emotional_influence: {emotion: joy, value: 0.5}\n"
      "  - name: mood\n    states: [calm, glad]\n    transitions:\n"
      "      - from: calm\n        to: glad\n        when:\n          - above_threshold: {emotion: joy, value: 0.3}\n"
      "        do:\n          - say: I feel great\n");
  // u_joy = 0.5 for this personality: each praise adds 0.25, the second crosses 0.3 (decay 0.1/s, dt 0).
  EXPECT_EQ(Said(feel.Update(Heard("you are nice", 0))), "");
  EXPECT_NEAR(feel.emotions().Intensity(Emotion::kJoy), 0.25, 1e-12);
  EXPECT_EQ(Said(feel.Update(Heard("you are kind", 0))), "mood: I feel great");
  EXPECT_EQ(*feel.EmotionNow().expression, Expression::kHappy);
  feel.Update(Heard("", 2.0));  // decay: 0.5 − 0.2
  EXPECT_NEAR(feel.emotions().Intensity(Emotion::kJoy), 0.3, 1e-12);
}

TEST(DialogueManager, TheEndActionEndsTheConversation) {
  DialogueManager m = Manager(
      "  - name: bye\n    states: [s, t]\n    transitions:\n"
      "      - from: s\n        to: t\n        when:\n          - heard: goodbye\n        do:\n          - say: bye\n          - end\n" +
      Answerer("other", 0, "*", "other"));
  EXPECT_FALSE(m.Update(Heard("goodbye")).steps.empty());
  EXPECT_TRUE(m.ended());
  EXPECT_TRUE(m.Update(Heard("hello")).steps.empty());
  EXPECT_TRUE(m.ExpectedPhrases().empty());
}

TEST(DialogueManager, MachinesGoingRoundInCirclesThroughAVariableAreStoppedNamingOne) {
  DialogueManager m = Manager(
      "  - name: ping\n    states: [a, b]\n    transitions:\n"
      "      - from: a\n        to: b\n        when:\n          - variable: {name: x, equals: '0'}\n"
      "      - from: b\n        to: a\n        when:\n          - variable: {name: x, equals: '0'}\n",
      0, "x: '0'");
  try {
    m.Update(Heard("hi"));
    FAIL();
  } catch (const DialogueError& e) {
    EXPECT_NE(std::string(e.what()).find("d.yaml: machine 'ping', state '"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("64 transitions in one update"), std::string::npos) << e.what();
  }
}

TEST(DialogueManager, ExpectedPhrasesAreThePatternsOfEveryRunningMachineHighestPriorityFirst) {
  DialogueManager m(LoadDialogue(testing::ExampleDialogue()), 0);
  const std::vector<std::string> expected = m.ExpectedPhrases();
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(expected.front(), "goodbye");  // farewell: priority 3
  EXPECT_NE(std::find(expected.begin(), expected.end(), "what is this place"), expected.end());
  EXPECT_EQ(expected.back(), "*");  // fallback: priority 0, last in the file
  EXPECT_EQ(std::find(expected.begin(), expected.end(), "my name is *"), expected.end());  // not asked yet
}

TEST(DialogueManager, PraiseRaisesJoyAndTheFaceShowsItInASeededRun) {
  DialogueManager m(LoadDialogue(testing::ExampleDialogue()), 7);
  m.Update({0.0, std::nullopt, {true, 1.5, true, true}});  // the greeting
  m.Update(Heard("my name is ann"));
  const double before = m.emotions().Intensity(Emotion::kJoy);
  const DialogueTurn praise = m.Update(Heard("you are wonderful"));
  EXPECT_EQ(praise.steps.at(0).machine, "feelings");
  const double after = m.emotions().Intensity(Emotion::kJoy);
  EXPECT_GT(after, before + 0.2) << before << " -> " << after;
  const EmotionSummary face = m.EmotionNow();
  ASSERT_TRUE(face.expression);
  EXPECT_EQ(*face.expression, Expression::kHappy);
  EXPECT_GT(face.expression_intensity, 0.4);
  EXPECT_GT(face.disc.evaluation, 0.0);
}

}  // namespace
}  // namespace arview::dialogue
