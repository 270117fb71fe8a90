#include "dialogue/pattern.h"

#include <gtest/gtest.h>

#include "dialogue/emotion.h"

namespace arview::dialogue {
namespace {

using Words = std::vector<std::string>;

TEST(Pattern, CapturesTheWordsOfAWildcardWhateverThePunctuationAndCase) {
  const Pattern p = Pattern::Compile("Hello my name is *", "test");
  EXPECT_EQ(Pattern::Compile("i am *", "test").Match("I am 25"), Words{"25"});  // heard digits are words
  EXPECT_EQ(p.text(), "hello my name is *");
  EXPECT_EQ(p.wildcards(), 1u);
  EXPECT_EQ(p.Match("Hello, my name is Ann!"), Words{"ann"});
  EXPECT_EQ(p.Match("hello my name is Ann Marie O'Neill"), Words{"ann marie o'neill"});
  EXPECT_FALSE(p.Match("hello my name is"));  // a wildcard takes at least one word
  EXPECT_FALSE(p.Match("well hello my name is ann"));
}

TEST(Pattern, SeveralWildcardsTakeAsFewWordsAsTheyCanFromTheLeft) {
  const Pattern p = Pattern::Compile("* likes *", "test");
  EXPECT_EQ(p.Match("bob really likes green tea"), (Words{"bob really", "green tea"}));
  EXPECT_EQ(p.Match("ann likes bob who likes tea"), (Words{"ann", "bob who likes tea"}));
  EXPECT_FALSE(p.Match("likes tea"));
  const Pattern any = Pattern::Compile("*", "test");
  EXPECT_EQ(any.Match("anything at all"), Words{"anything at all"});
  EXPECT_FALSE(any.Match(""));
  EXPECT_FALSE(any.Match("?!"));
}

TEST(Pattern, WordsWithoutWildcardsMatchExactly) {
  const Pattern p = Pattern::Compile("  what is   this place ", "test");
  EXPECT_EQ(p.text(), "what is this place");
  EXPECT_EQ(p.Match("What is this place?"), Words{});
  EXPECT_FALSE(p.Match("what is this"));
  EXPECT_FALSE(p.Match("what is this place now"));
}

TEST(Pattern, ManyWildcardsOverALongInputFinishQuickly) {
  const Pattern p = Pattern::Compile("* a * a * a * a * a * a * a * a * b", "test");
  std::string heard;
  for (int i = 0; i < 600; ++i) heard += "a ";
  EXPECT_FALSE(p.Match(heard));  // no "b": every split fails, each (token, word) pair tried once
  EXPECT_TRUE(p.Match(heard + "b"));
}

TEST(Pattern, WhatCannotCompileIsOneLineSayingWhy) {
  std::string long_pattern;
  for (int i = 0; i < 65; ++i) long_pattern += "a ";
  struct Case {
    std::string pattern;
    std::string why;
  } cases[] = {
      {"", "no word"},
      {"   ", "no word"},
      {"hello, *", "',' at character 6 is not a letter a-z"},
      {"i am 25", "numbers are spelled out"},
      {"caf\xc3\xa9 *", "not a letter a-z"},
      {"hel*o", "inside a word"},
      {"hello *there", "inside a word"},
      {"* *", "side by side"},
      {"* a * a * a * a * a * a * a * a * a *", "more than 9 wildcards"},
      {"tab\x01", "\\x01"},
      {long_pattern, "65 words and wildcards, more than 64"},
  };
  for (const Case& c : cases) {
    try {
      Pattern::Compile(c.pattern, "d.yaml:3");
      ADD_FAILURE() << "compiled '" << c.pattern << "'";
    } catch (const DialogueError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("d.yaml:3: pattern '", 0), 0u) << message;
      EXPECT_NE(message.find("cannot compile"), std::string::npos) << message;
      EXPECT_NE(message.find(c.why), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace arview::dialogue
