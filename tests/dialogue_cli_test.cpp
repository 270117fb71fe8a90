// arview dialogue check and chat, run as the user runs them (docs/dialogue.md).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/run_command.h"

namespace {

using arview::testing::LineCount;
using arview::testing::RunArview;

std::string Example() {
  const char* source = std::getenv("ARVIEW_SOURCE_DIR");
  return (std::filesystem::path(source ? source : ".") / "docs/examples/guide-dialogue.yaml").string();
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / ("arview_dialogue_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

const std::string kHeader =
    "dialogue: 1\n"
    "personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, agreeableness: 0.5, neuroticism: 0.5}\n"
    "decay: 0.1\n"
    "machines:\n";

TEST(DialogueCli, CheckPassesTheDemoDialogue) {
  const auto r = RunArview({"dialogue", "check", Example()});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("6 machines"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": ok"), std::string::npos) << r.out;
}

TEST(DialogueCli, CheckNamesUnreachableStatesAndExitsNonZero) {
  const std::string file = WriteTemp("island.yaml", kHeader +
                                                        "  - name: m\n    states: [s, t, island]\n    transitions:\n"
                                                        "      - {from: s, to: t, when: [{heard: hello}]}\n");
  const auto r = RunArview({"dialogue", "check", file});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("machine 'm', state 'island': unreachable"), std::string::npos) << r.out;
  EXPECT_EQ(LineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("1 error(s)"), std::string::npos) << r.err;
  std::filesystem::remove(file);
}

TEST(DialogueCli, CheckNamesEveryUndefinedName) {
  const std::string file = WriteTemp("undefined.yaml", kHeader +
                                                           "  - name: m\n    states: [s, t]\n    transitions:\n"
                                                           "      - {from: s, to: nowhere}\n"
                                                           "      - {from: s, to: t, do: [{say: 'hi ${who} $1'}]}\n");
  const auto r = RunArview({"dialogue", "check", file});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("error: " + file + ":8: machine 'm', state 's': to 'nowhere' is not one of the machine's states"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("state 's': variable 'who' is not defined"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("state 's': $1 is not defined"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("3 error(s)"), std::string::npos) << r.err;
  std::filesystem::remove(file);
}

TEST(DialogueCli, ABadDialogueIsOneLineNamingFileMachineAndState) {
  const std::string file = WriteTemp("bad.yaml", kHeader +
                                                     "  - name: m\n    states: [s, t]\n    transitions:\n"
                                                     "      - {from: s, to: t, do: [{emotional_influence: {emotion: glee, value: 1}}]}\n");
  for (const char* sub : {"check", "chat"}) {
    const auto r = RunArview({"dialogue", sub, file});
    EXPECT_EQ(r.exit_code, 1) << sub;
    EXPECT_EQ(LineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(file + ":8: machine 'm', state 's': unknown emotion 'glee'"), std::string::npos) << r.err;
  }
  const auto missing = RunArview({"dialogue", "check", "/nonexistent/d.yaml"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(LineCount(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("/nonexistent/d.yaml"), std::string::npos) << missing.err;
  std::filesystem::remove(file);
}

TEST(DialogueCli, ChatConversesThroughTheStandardInput) {
  const std::string script = WriteTemp("script.txt",
                                       "hello my name is Bob\n"
                                       "what is this place\n"
                                       "you look great\n"
                                       "no\n"
                                       "/expect\n"
                                       "goodbye\n");
  const auto r = RunArview({"dialogue", "chat", Example(), "--seed", "3"}, script);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("welcome: <gesture name=\"Wave\"/>Hello! I am Ada"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Nice to meet you, bob."), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("questions: This is the map room."), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("feelings: <face expr=\"happy\" intensity=\"0.8\"/>Thank you, bob!"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[feelings] joy"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("I am sorry to hear that, bob."), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("farewell: <gesture name=\"Wave\"/>Goodbye, bob. Come back soon."), std::string::npos) << r.out;
  // No prompt when the input is not a terminal.
  EXPECT_NE(r.out.rfind("> ", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("\n> "), std::string::npos) << r.out;
  std::filesystem::remove(script);
}

TEST(DialogueCli, HelpDocumentsBothSubcommandsAndTheFlags) {
  const auto r = RunArview({"dialogue", "chat", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--seed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--seconds-per-line"), std::string::npos) << r.out;
  const auto top = RunArview({"dialogue", "--help"});
  EXPECT_NE(top.out.find("check"), std::string::npos) << top.out;
  EXPECT_NE(top.out.find("chat"), std::string::npos) << top.out;
}

}  // namespace
