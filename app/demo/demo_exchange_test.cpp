// The demo's scripted exchange (issue 54) without the demo: its built-in dialogue, fed its
// visitor.wav through the session's dialogue as the demo's replay feeds it (the WAV paced by the
// frame clock), follows the expected path: each question heard as said, the visitor machine
// answering with the expected line, the conversation ended, joy on the face at the end.

#include "app/demo/demo_exchange.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include "app/session/test_dialogue_exchange.h"
#include "dialogue/dialogue_file.h"
#include "tests/support/sanitizer_slowdown.h"

namespace arview::app {
namespace {

namespace fs = std::filesystem;

fs::path TempFolder() {
  const fs::path dir = fs::temp_directory_path() / ("arview_demo_exchange_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(DemoExchange, TheDialogueLoadsWithNothingUnreachable) {
  const fs::path dir = TempFolder();
  const DemoExchange files = WriteDemoExchange(dir);
  EXPECT_TRUE(dialogue::CheckDialogueFile(files.dialogue).empty());
  ASSERT_EQ(files.line_end_s.size(), VisitorLines().size());
  for (std::size_t i = 0; i < VisitorLines().size(); ++i) EXPECT_GT(files.line_end_s[i], VisitorLines()[i].start_s + 0.5);
  EXPECT_NEAR(static_cast<double>(audio::ReadWav(files.wav).samples.size()) / audio::kSpeechRate,
              files.line_end_s.back() + 1.0, 1e-3);
  fs::remove_all(dir);
}

TEST(DemoExchange, TheVisitorsQuestionsAreHeardAndAnsweredOnTheExpectedPath) {
  if (!fs::exists(testing::kPocketsphinxModel)) {
    if (std::getenv("ARVIEW_REQUIRE_DATA")) ADD_FAILURE() << "no " << testing::kPocketsphinxModel;
    GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  }
  const fs::path dir = TempFolder();
  const DemoExchange files = WriteDemoExchange(dir);
  // Four times faster than real time (the demo's unpaced replay runs two to three times): the
  // path does not depend on timing, only on what is heard.
  const double speed = 4.0 / arview::testing::kSanitizerSlowdown;
  const testing::ExchangeRun run = testing::RunExchange(files.dialogue, files.wav, "slt", speed, 25.0);
  EXPECT_TRUE(run.problems.empty()) << ::testing::PrintToString(run.problems);
  ASSERT_EQ(run.turns.size(), VisitorLines().size()) << ::testing::PrintToString(run.results);
  const char* replies[] = {"This is your own room", "Thank you!"};
  for (std::size_t i = 0; i < run.turns.size(); ++i) {
    SCOPED_TRACE(i);
    const DialogueTurnRecord& turn = run.turns[i];
    EXPECT_EQ(turn.heard, VisitorLines()[i].text);
    EXPECT_GT(turn.confidence, 0.0);
    EXPECT_EQ(turn.machine, kDemoDialogueMachine);
    EXPECT_NE(turn.said.find(replies[i]), std::string::npos) << turn.said;
    EXPECT_NEAR(turn.heard_end_s, files.line_end_s[i], 0.3);  // the WAV's own time: the frame clock's
    EXPECT_GT(turn.reply_start_s, turn.heard_end_s);
  }
  EXPECT_TRUE(run.ended);
  ASSERT_EQ(run.utterances.size(), 2u);
  EXPECT_GT(run.joy.back(), 0.3);
  EXPECT_GT(run.expression_weight.back(), 0.2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview::app
