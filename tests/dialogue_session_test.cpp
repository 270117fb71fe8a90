// The character listens and answers end to end (issue 54): the user's side of a scripted exchange
// spoken by three Flite voices into a WAV, heard through the session's dialogue as `replay
// --dialogue --audio-in` hears it (the WAV paced by the frame clock, recognition on its own
// thread, the replies synthesized on the speech queue's and said on the frame path), the
// dialogue's expected path followed every time, each reply's audio written.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "app/session/test_dialogue_exchange.h"
#include "tests/support/test_data.h"

namespace {

namespace fs = std::filesystem;
using namespace arview;
using app::testing::kAnsweringMachines;
using app::testing::kUserLines;

fs::path GuideDialogue() { return app::testing::SpokenDialogue(arview::testing::SourceDir()); }

fs::path TempFolder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("arview_dialogue_session_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool ModelMissing() {
  if (fs::exists(app::testing::kPocketsphinxModel)) return false;
  if (std::getenv("ARVIEW_REQUIRE_DATA")) ADD_FAILURE() << "no " << app::testing::kPocketsphinxModel;
  return true;
}

TEST(DialogueSession, AScriptedSpokenExchangeFollowsTheGuidesPathInThreeVoices) {
  if (ModelMissing()) GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  for (const char* voice : {"slt", "rms", "awb"}) {
    SCOPED_TRACE(voice);
    const fs::path dir = TempFolder(voice);
    const app::testing::UserSide user = app::testing::SynthesizeUserSide(kUserLines, speech::VoiceFromName(voice));
    app::testing::WriteSpeechWav(dir / "talk.wav", user.samples);
    // Three times faster than real time: recognition and synthesis keep up on the loaded machine,
    // and the path does not depend on timing (the viewer stands still in front).
    const app::testing::ExchangeRun run = app::testing::RunExchange(GuideDialogue(), dir / "talk.wav", "slt", 3.0, 90);
    EXPECT_TRUE(run.problems.empty()) << run.problems.front();
    EXPECT_TRUE(run.ended);
    std::vector<std::string> machines, heard;
    for (const app::DialogueTurnRecord& t : run.turns) {
      machines.push_back(t.machine);
      if (!t.heard.empty()) heard.push_back(t.heard);
    }
    std::string results;
    for (const std::string& r : run.results) results += "\n  " + r;
    EXPECT_EQ(machines, kAnsweringMachines) << "recognitions:" << results;
    EXPECT_EQ(heard, kUserLines) << "recognitions:" << results;
    ASSERT_EQ(run.utterances.size(), kAnsweringMachines.size());
    for (std::size_t i = 0; i < run.turns.size(); ++i) {
      const app::DialogueTurnRecord& t = run.turns[i];
      EXPECT_GE(t.reply_start_s, t.time_s) << t.said;
      if (t.heard.empty()) continue;
      EXPECT_GT(t.confidence, 0.06) << t.heard;
      // The heard words end where the WAV's line ends, within the speech's own trailing silence.
      const std::size_t line = std::find(kUserLines.begin(), kUserLines.end(), t.heard) - kUserLines.begin();
      ASSERT_LT(line, user.line_end_s.size());
      EXPECT_NEAR(t.heard_end_s, user.line_end_s[line], 0.5) << t.heard;
      EXPECT_GT(t.LatencyS(), 0) << t.heard;
    }
    for (const speech::Utterance& u : run.utterances) {
      const fs::path file = dir / ("reply_" + std::to_string(u.sequence) + ".wav");
      app::testing::WriteSpeechWav(file, u.line->samples);
      EXPECT_GT(u.line->samples.size(), 8000u) << u.origin;  // at least half a second said
      EXPECT_GT(fs::file_size(file), 16000u);
    }
    fs::remove_all(dir);
  }
}

// Praise raises joy, and the face shows it: the expression's weight in the per-frame stats
// (DialogueFrame::expression_weight) rises after "you are very kind".
TEST(DialogueSession, PraiseRaisesJoyAndTheExpressionWeightInASeededRun) {
  if (ModelMissing()) GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  const fs::path dir = TempFolder("praise");
  const app::testing::UserSide user = app::testing::SynthesizeUserSide({"you are very kind"}, speech::Voice::kSlt, 1.0, 3.0);
  app::testing::WriteSpeechWav(dir / "talk.wav", user.samples);
  const app::testing::ExchangeRun run = app::testing::RunExchange(GuideDialogue(), dir / "talk.wav", "slt", 3.0, 6.0, 7);
  const std::size_t praised = static_cast<std::size_t>(user.line_end_s[0] * 30);
  ASSERT_GT(run.joy.size(), praised + 30);
  const auto before_joy = run.joy[praised - 1];
  const auto before_weight = run.expression_weight[praised - 1];
  EXPECT_GT(run.joy.back(), before_joy + 0.2);
  EXPECT_GT(run.expression_weight.back(), before_weight + 0.15);
  fs::remove_all(dir);
}

}  // namespace
