#include "dialogue/chat.h"

#include <gtest/gtest.h>

#include <sstream>

#include "dialogue/test_dialogues.h"

namespace arview::dialogue {
namespace {

std::string Chat(const std::string& typed, std::uint64_t seed = 0) {
  DialogueManager manager(LoadDialogue(testing::ExampleDialogue()), seed);
  std::istringstream in(typed);
  std::ostringstream out;
  RunChat(manager, in, out, ChatOptions{});
  return out.str();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The machines that spoke, in order (a line "machine: text", not the status or notes).
std::vector<std::string> Speakers(const std::string& output) {
  std::vector<std::string> speakers;
  for (const std::string& line : Lines(output)) {
    const std::size_t colon = line.find(": ");
    if (colon == std::string::npos || line.front() == '[' || line.front() == '(' || line.front() == ' ') continue;
    speakers.push_back(line.substr(0, colon));
  }
  return speakers;
}

TEST(DialogueChat, AScriptedExchangeFollowsTheDemosExpectedPath) {
  const std::string out = Chat(
      "Hello, my name is Ann\n"
      "What is this place?\n"
      "You are wonderful\n"
      "Yes, I love it\n"
      "blah blah\n"
      "Goodbye\n"
      "this is never read\n");
  EXPECT_EQ(Speakers(out), (std::vector<std::string>{"welcome", "welcome", "questions", "questions", "feelings", "welcome",
                                                     "fallback", "farewell"}))
      << out;
  EXPECT_NE(out.find("welcome: <gesture name=\"Wave\"/>Hello! I am Ada"), std::string::npos) << out;
  EXPECT_NE(out.find("Nice to meet you, ann."), std::string::npos) << out;
  EXPECT_NE(out.find("questions: [gesture Point]"), std::string::npos) << out;
  EXPECT_NE(out.find("I am glad, ann."), std::string::npos) << out;
  EXPECT_NE(out.find("Goodbye, ann. Come back soon."), std::string::npos) << out;
  EXPECT_NE(out.find("(the conversation has ended)"), std::string::npos) << out;
  EXPECT_NE(out.find("[feelings] joy 0."), std::string::npos) << out;  // praise: joy 0.5·0.75 on top of 0.2
  EXPECT_EQ(out.find("never read"), std::string::npos) << out;
}

TEST(DialogueChat, CommandsMoveTimeAndTheViewerAndListWhatCanBeHeard) {
  const std::string out = Chat(
      "/expect\n"
      "/viewer behind\n"
      "/wait 3\n"
      "/viewer front\n"
      "/viewer lost\n"
      "/wait 4\n"
      "/viewer tracked\n"
      "/emotions\n"
      "/viewer sideways\n"
      "/wait soon\n"
      "/dance\n"
      "/quit\n"
      "goodbye\n");
  EXPECT_NE(out.find("  my name is *\n"), std::string::npos) << out;
  EXPECT_NE(out.find("viewer: Are you behind me?"), std::string::npos) << out;
  EXPECT_NE(out.find("viewer: <gaze at=\"viewer\"/>There you are."), std::string::npos) << out;
  EXPECT_NE(out.find("viewer: Where did you go?"), std::string::npos) << out;
  EXPECT_NE(out.find("viewer: Welcome back."), std::string::npos) << out;
  EXPECT_NE(out.find("  relief "), std::string::npos) << out;
  EXPECT_NE(out.find("/viewer does not know 'sideways'"), std::string::npos) << out;
  EXPECT_NE(out.find("/wait needs a number of seconds"), std::string::npos) << out;
  EXPECT_NE(out.find("unknown command '/dance'"), std::string::npos) << out;
  EXPECT_EQ(out.find("Goodbye"), std::string::npos) << out;  // /quit came first
}

TEST(DialogueChat, TheStatusLineNamesTheMachineTheDominantEmotionAndTheFace) {
  DialogueManager manager(LoadDialogue(testing::ExampleDialogue()), 0);
  EXPECT_EQ(StatusLine(manager), "[-] neutral, activation 0.00");
  manager.Update({0.0, std::nullopt, {true, 1.0, true, true}});
  EXPECT_EQ(StatusLine(manager).rfind("[welcome] hope ", 0), 0u) << StatusLine(manager);
  EXPECT_NE(StatusLine(manager).find(" -> happy "), std::string::npos) << StatusLine(manager);
}

}  // namespace
}  // namespace arview::dialogue
