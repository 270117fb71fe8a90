// The character listens and answers end to end (issue 54): the user's side of a scripted exchange
// spoken by three Flite voices into a WAV, heard through the session's dialogue as `replay
// --dialogue --audio-in` hears it (the WAV paced by the frame clock, recognition on its own
// thread, the replies synthesized on the speech queue's and said on the frame path), the
// dialogue's expected path followed every time, each reply's audio written.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <unistd.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "app/session/test_dialogue_exchange.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/emulated_sound.h"
#include "tests/support/graffiti_map.h"
#include "tests/support/run_command.h"
#include "tests/support/test_data.h"
#include "tests/support/virtual_display.h"
#include "tracker/test_planar_scene.h"

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

// Push-to-talk (`--push-to-talk`, the window's space bar): the key is pressed as the window's key
// handler presses it (SessionDialogue::TogglePushToTalk), open before the second of two lines and
// closed after it. The first line, said with the key up, is not even decoded; the second is heard
// and answered, and the HUD says when the character listens.
TEST(DialogueSession, PushToTalkHearsOnlyWhatIsSaidBetweenTwoPressesOfTheKey) {
  if (ModelMissing()) GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  const fs::path dir = TempFolder("push_to_talk");
  constexpr double kGap = 3.0;
  const app::testing::UserSide user =
      app::testing::SynthesizeUserSide({"what is this place", "you are very kind"}, speech::Voice::kSlt, 1.0, kGap);
  app::testing::WriteSpeechWav(dir / "talk.wav", user.samples);
  const double open_s = user.line_end_s[0] + kGap - 1.0, close_s = user.line_end_s[1] + 0.3;
  int presses = 0;
  app::DialogueSessionOptions o;
  o.push_to_talk = true;
  const app::testing::ExchangeRun run = app::testing::RunExchange(
      GuideDialogue(), dir / "talk.wav", "slt", 3.0, close_s + 2.0, 7, o, [&](double t, app::SessionDialogue& session) {
        const bool due = (presses == 0 && t >= open_s) || (presses == 1 && t >= close_s);
        if (due) {
          EXPECT_EQ(session.TogglePushToTalk(), ++presses == 1);  // open, then closed
        }
      });
  EXPECT_EQ(presses, 2);
  ASSERT_EQ(run.results.size(), 1u) << ::testing::PrintToString(run.results);
  EXPECT_NE(run.results[0].find("\"you are very kind\""), std::string::npos) << run.results[0];
  EXPECT_NE(run.results[0].find(" taken"), std::string::npos) << run.results[0];
  ASSERT_EQ(run.turns.size(), 2u);
  EXPECT_EQ(run.turns[0].heard, "");  // the greeting on the viewer's approach
  EXPECT_EQ(run.turns[1].heard, "you are very kind");
  EXPECT_EQ(run.turns[1].machine, "feelings");
  // The HUD: "press space to speak" with the key up, "listening" between the presses.
  const std::size_t before = static_cast<std::size_t>(open_s * 30) - 5, during = static_cast<std::size_t>(open_s * 30) + 5;
  ASSERT_GT(run.talk_hud.size(), during);
  EXPECT_EQ(run.talk_hud[before], "talk: press space to speak");
  EXPECT_EQ(run.talk_hud[during], "talk: listening, press space when done");
  EXPECT_EQ(run.talk_hud.back(), "talk: press space to speak")
      << run.talk_hud.size() << " frames; " << ::testing::PrintToString(std::vector<std::string>(run.talk_hud.end() - 4, run.talk_hud.end()));
  fs::remove_all(dir);
}

// The graffiti wall's host: greets the viewer once tracked, then answers "what is this place".
void WriteHostDialogue(const fs::path& file) {
  std::ofstream(file) << "dialogue: 1\n"
                         "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, "
                         "agreeableness: 0.5, neuroticism: 0.5}\n"
                         "decay: 0.01\n"
                         "machines:\n"
                         "  - name: host\n"
                         "    states: [waiting, greeted, answered]\n"
                         "    final: [answered]\n"
                         "    transitions:\n"
                         "      - {from: waiting, to: greeted, when: [{viewer_tracked: true}], do: [{say: Hello.}]}\n"
                         "      - from: greeted\n"
                         "        to: answered\n"
                         "        when: [{heard: what is this place}]\n"
                         "        do: [{say: This is the graffiti wall.}, {emotional_influence: {emotion: joy, value: 0.5}}]\n";
}

// `arview replay --dialogue --audio-in --stats` as the user runs it: the graffiti map's views
// (tests/support/graffiti_map.h) replayed four times over, the figure standing in front of the
// first localized view, a WAV saying "what is this place". The greeting and the answer are the
// stats' dialogue_turns, the frame the phrase was heard says so, and every frame has the dialogue.
class DialogueReplay : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(tracker::testing::kGraffitiTexture, "Debian package opencv-doc");
    dir_ = TempFolder("replay");
    ::setenv("ARVIEW_CACHE_DIR", (dir_ / "cache").c_str(), 1);
    arview::testing::WriteGraffitiMapFolder(dir_ / "map");
    arview::testing::WriteGraffitiViews(dir_ / "views");
    WriteHostDialogue(dir_ / "d.yaml");
  }
  void TearDown() override {
    ::unsetenv("ARVIEW_CACHE_DIR");
    if (!HasFailure()) fs::remove_all(dir_);
  }
  arview::testing::CommandResult Replay(std::vector<std::string> extra) {
    std::vector<std::string> args = {"replay", (dir_ / "views").string(), "--map", (dir_ / "map").string(), "--out", "null"};
    args.insert(args.end(), extra.begin(), extra.end());
    return arview::testing::RunArview(args);
  }
  fs::path dir_;
};

TEST_F(DialogueReplay, TheCharacterAnswersWhatTheWavSaysAndTheStatsRecordTheTurns) {
  if (ModelMissing()) GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  const app::testing::UserSide user = app::testing::SynthesizeUserSide({"what is this place"}, speech::Voice::kSlt, 0.5, 2.0);
  app::testing::WriteSpeechWav(dir_ / "talk.wav", user.samples);
  const auto r = Replay({"--loop", "4", "--hud", "--dialogue", (dir_ / "d.yaml").string(), "--audio-in",
                         (dir_ / "talk.wav").string(), "--stats", (dir_ / "s.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir_ / "s.json"));
  ASSERT_TRUE(stats.contains("dialogue_turns")) << r.err;
  const nlohmann::json& turns = stats["dialogue_turns"];
  ASSERT_EQ(turns.size(), 2u) << turns.dump(1);
  EXPECT_EQ(turns[0]["said"], "Hello.");
  EXPECT_EQ(turns[0]["heard"], "");
  EXPECT_EQ(turns[1]["heard"], "what is this place");
  EXPECT_EQ(turns[1]["machine"], "host");
  EXPECT_GT(turns[1]["confidence"].get<double>(), 0.06);
  EXPECT_NEAR(turns[1]["heard_end_s"].get<double>(), user.line_end_s[0], 0.5);
  EXPECT_GT(turns[1]["latency_ms"].get<double>(), 0);
  int heard_frames = 0;
  for (const nlohmann::json& f : stats["frames"]) {
    ASSERT_TRUE(f.contains("dialogue"));
    if (f["dialogue"].contains("heard")) heard_frames += f["dialogue"]["heard"]["text"] == "what is this place";
  }
  EXPECT_EQ(heard_frames, 1);
  EXPECT_EQ(stats["frames"].back()["dialogue"]["emotion"], "joy");
  EXPECT_GT(stats["frames"].back()["dialogue"]["expression_weight"].get<double>(), 0.0);
}

// `arview run --dialogue --mic` end to end, as a user runs it: the emulated camera
// (tests/support/emulated_camera.h) looping the graffiti views, the emulated microphone
// (tests/support/emulated_sound.h: ALSA's `file` plugin, paced by arview's capture clock) saying
// "what is this place" after 3 s of silence, Ctrl-C after 10 s. The line is heard in the live
// session and answered, and --stats has the turn.
class DialogueLive : public DialogueReplay {};

TEST_F(DialogueLive, RunHearsALineSpokenIntoTheMicrophoneAndAnswersIt) {
  if (ModelMissing()) GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  const arview::testing::EmulatedSound sound(dir_ / "sound");
  const app::testing::UserSide user = app::testing::SynthesizeUserSide({"what is this place"}, speech::Voice::kSlt, 3.0, 2.0);
  sound.SetMicrophoneInput(user.samples);
  const std::vector<std::string> args = {"run", "--device", arview::testing::kEmulatedCamera, "--map",
                                         (dir_ / "map").string(), "--out", "null", "--audio-out", "none", "--dialogue",
                                         (dir_ / "d.yaml").string(), "--mic", arview::testing::EmulatedSound::kMicrophone,
                                         "--stats", (dir_ / "s.json").string()};
  const auto r = arview::testing::RunWithEmulatedCamera(
      args, {{"ARVIEW_FAKE_CAMERA_RECORDING", (dir_ / "views").string()}}, dir_, {0, 0},
      10 * arview::testing::kSanitizerSlowdown);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("microphone"), std::string::npos) << r.err;  // opened, and never lost
  const nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir_ / "s.json"));
  ASSERT_TRUE(stats.contains("dialogue_turns")) << r.err;
  const nlohmann::json& turns = stats["dialogue_turns"];
  ASSERT_EQ(turns.size(), 2u) << turns.dump(1) << r.err;
  EXPECT_EQ(turns[0]["said"], "Hello.");
  EXPECT_EQ(turns[1]["heard"], "what is this place");
  EXPECT_EQ(turns[1]["said"], "This is the graffiti wall.");
  EXPECT_GT(turns[1]["confidence"].get<double>(), 0.06);
  EXPECT_GE(turns[1]["reply_start_s"].get<double>(), turns[1]["time_s"].get<double>()) << "the answer was not said";
  std::printf("run --mic: heard \"%s\" (confidence %.3f), answered %.0f ms after the words ended\n",
              turns[1]["heard"].get<std::string>().c_str(), turns[1]["confidence"].get<double>(),
              turns[1]["latency_ms"].get<double>());
}

// The space bar in the window under Xvfb, as a user presses it: `replay --paced --out window
// --push-to-talk` on the graffiti views, a WAV saying "what is this place" 4 s after the first
// frame; space pressed once the window shows frames (about 1 s in) and again 7 s later, then Esc.
// The phrase between the presses is heard and answered.
class DialogueWindow : public arview::testing::XSessionTest<::testing::Test> {};
using arview::testing::ReadWholeFile;
using arview::testing::ShellQuote;

TEST_F(DialogueWindow, TheSpaceBarOpensListeningAndThePhraseBetweenTwoPressesIsAnswered) {
  if (ModelMissing()) GTEST_SKIP() << "needs the Debian package pocketsphinx-en-us";
  ARVIEW_REQUIRE_DATA_PATH(tracker::testing::kGraffitiTexture, "Debian package opencv-doc");
  StartXSession("dialogue_window");
  if (HasFatalFailure() || IsSkipped()) return;
  arview::testing::WriteGraffitiMapFolder(dir_ / "map");
  arview::testing::WriteGraffitiViews(dir_ / "views");
  WriteHostDialogue(dir_ / "d.yaml");
  const app::testing::UserSide user = app::testing::SynthesizeUserSide({"what is this place"}, speech::Voice::kSlt, 4.0, 6.0);
  app::testing::WriteSpeechWav(dir_ / "talk.wav", user.samples);
  const char* bin = std::getenv("ARVIEW_BIN");
  const std::string line =
      "exec env DISPLAY=" + display_->name() + " ARVIEW_CACHE_DIR=" + ShellQuote((dir_ / "cache").string()) + " " +
      ShellQuote(bin ? bin : "arview") + " replay " + ShellQuote((dir_ / "views").string()) + " --map " +
      ShellQuote((dir_ / "map").string()) + " --paced --loop 1000 --out window --audio-out none --push-to-talk --dialogue " +
      ShellQuote((dir_ / "d.yaml").string()) + " --audio-in " + ShellQuote((dir_ / "talk.wav").string()) + " --stats " +
      ShellQuote((dir_ / "s.json").string()) + " 2>" + ShellQuote((dir_ / "stderr.txt").string());
  arview::testing::Child app({"sh", "-c", line}, (dir_ / "stdout.txt").string());
  const std::string id = WaitForLiveWindow(app);
  ASSERT_FALSE(id.empty()) << "no window with a live status appeared\n" << ReadWholeFile((dir_ / "stderr.txt").string());
  const std::string key = "DISPLAY=" + display_->name() + " xdotool key --window " + id + " ";
  EXPECT_EQ(std::system((key + "space >/dev/null 2>&1").c_str()), 0);
  std::this_thread::sleep_for(std::chrono::seconds(7));
  EXPECT_EQ(std::system((key + "space >/dev/null 2>&1").c_str()), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the words decoded, the answer made
  (void)std::system((key + "Escape >/dev/null 2>&1").c_str());
  ASSERT_EQ(app.Wait(10), 0) << ReadWholeFile((dir_ / "stderr.txt").string());
  const nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir_ / "s.json"));
  ASSERT_TRUE(stats.contains("dialogue_turns"));
  const nlohmann::json& turns = stats["dialogue_turns"];
  ASSERT_EQ(turns.size(), 2u) << turns.dump(1);
  EXPECT_EQ(turns[1]["heard"], "what is this place");
  EXPECT_EQ(turns[1]["said"], "This is the graffiti wall.");
}

TEST_F(DialogueReplay, BadInputsAreOneLineEach) {
  auto r = Replay({"--audio-in", (dir_ / "d.yaml").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--audio-in needs --dialogue"), std::string::npos) << r.err;
  // Push-to-talk's key is pressed in a window: refused without one, and without anything to hear.
  r = Replay({"--dialogue", (dir_ / "d.yaml").string(), "--audio-in", (dir_ / "d.yaml").string(), "--push-to-talk"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--push-to-talk needs --out window"), std::string::npos) << r.err;
  r = Replay({"--dialogue", (dir_ / "d.yaml").string(), "--push-to-talk"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--push-to-talk needs something to hear"), std::string::npos) << r.err;
  // Not a WAV: the audio module's line, before any frame.
  r = Replay({"--dialogue", (dir_ / "d.yaml").string(), "--audio-in", (dir_ / "d.yaml").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(arview::testing::LineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("d.yaml"), std::string::npos) << r.err;
  // A phrase the recognizer cannot hear (a word not in its dictionary): named before any frame.
  std::ofstream(dir_ / "bad.yaml") << "dialogue: 1\n"
                                      "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, "
                                      "agreeableness: 0.5, neuroticism: 0.5}\n"
                                      "decay: 0.1\n"
                                      "machines:\n"
                                      "  - {name: m, states: [s, t], transitions: [{from: s, to: t, when: [{heard: hello xyzzyq}]}]}\n";
  const app::testing::UserSide user = app::testing::SynthesizeUserSide({"hello"}, speech::Voice::kSlt, 0.5, 0.5);
  app::testing::WriteSpeechWav(dir_ / "talk.wav", user.samples);
  r = Replay({"--dialogue", (dir_ / "bad.yaml").string(), "--audio-in", (dir_ / "talk.wav").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("'xyzzyq'"), std::string::npos) << r.err;
}

}  // namespace
