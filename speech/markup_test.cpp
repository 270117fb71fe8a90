#include "speech/markup.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace arview::speech {
namespace {

using ::testing::HasSubstr;

TEST(Markup, TakesTheTagsOutAndGivesEachTheWordItStandsBefore) {
  const MarkedLine line = ParseMarkup(
      "<gaze at=\"viewer\"/>Oh, <gesture name=\"Wave\"/>hello there! <face expr=\"happy\" intensity=\"0.6\"/> "
      "Nice to see you.<gesture name='bow_2'/>",
      "test");
  EXPECT_EQ(line.text, "Oh, hello there!  Nice to see you.");
  ASSERT_EQ(line.words.size(), 7u);
  EXPECT_EQ(line.words[1], "hello");
  ASSERT_EQ(line.tags.size(), 4u);
  EXPECT_EQ(line.tags[0].kind, TagKind::kGaze);
  EXPECT_EQ(line.tags[0].target, "viewer");
  EXPECT_EQ(line.tags[0].word, 0u);
  EXPECT_EQ(line.tags[0].position, 1u);
  EXPECT_EQ(line.tags[1].kind, TagKind::kGesture);
  EXPECT_EQ(line.tags[1].target, "Wave");
  EXPECT_EQ(line.tags[1].word, 1u);
  EXPECT_EQ(line.tags[2].kind, TagKind::kFace);
  EXPECT_EQ(line.tags[2].target, "happy");
  EXPECT_DOUBLE_EQ(line.tags[2].intensity, 0.6);
  EXPECT_EQ(line.tags[2].word, 3u);
  EXPECT_EQ(line.tags[3].target, "bow_2");
  EXPECT_EQ(line.tags[3].word, 7u);  // at the end
}

TEST(Markup, PlainTextHasNoTags) {
  const MarkedLine line = ParseMarkup("  just   words\there ", "test");
  EXPECT_EQ(line.text, "  just   words\there ");
  EXPECT_EQ(line.words, (std::vector<std::string>{"just", "words", "here"}));
  EXPECT_TRUE(line.tags.empty());
  EXPECT_DOUBLE_EQ(ParseMarkup("<face expr=\"sad\"/>x", "t").tags[0].intensity, 1.0);
}

std::string ErrorOf(std::string_view markup) {
  try {
    (void)ParseMarkup(markup, "scene.yaml, line 3");
  } catch (const SpeechError& error) {
    return error.what();
  }
  return "no error";
}

TEST(Markup, BadInputIsOneErrorNamingTheProblemAndWhere) {
  EXPECT_EQ(ErrorOf("Hi <wave/> there"),
            "scene.yaml, line 3: the unknown tag <wave> (the tags are gesture, face or gaze) at character 4");
  EXPECT_EQ(ErrorOf("Hi <gesture nam=\"Wave\"/>"),
            "scene.yaml, line 3: the unknown attribute 'nam' of <gesture> (it takes name) at character 13");
  EXPECT_THAT(ErrorOf("Hi <face expr=\"happy\">there"), HasSubstr("<face> is not closed with \"/>\" at character 4"));
  EXPECT_THAT(ErrorOf("Hi <face expr=\"happy\""), HasSubstr("not closed with \"/>\" at character 4"));
  EXPECT_THAT(ErrorOf("Hi <face expr=\"happy/>"), HasSubstr("not closed (a quote is open) at character 4"));
  EXPECT_THAT(ErrorOf("Hi <face expr=\"happy\" intensity=\"1.5\"/>"),
              HasSubstr("the intensity 1.5 of <face> is outside [0, 1] at character 23"));
  EXPECT_THAT(ErrorOf("<face expr=\"happy\" intensity=\"-0.1\"/>"), HasSubstr("outside [0, 1]"));
  EXPECT_THAT(ErrorOf("<face expr=\"happy\" intensity=\"nan\"/>"), HasSubstr("is not a number"));
  EXPECT_THAT(ErrorOf("<face expr=\"happy\" intensity=\"0.5x\"/>"), HasSubstr("is not a number"));
  EXPECT_THAT(ErrorOf("<face intensity=\"0.5\"/>"), HasSubstr("<face> without its expr=\"...\" at character 1"));
  EXPECT_THAT(ErrorOf("<gaze at=\"a\" at=\"b\"/>"), HasSubstr("'at' repeated"));
  EXPECT_THAT(ErrorOf("<gaze at=\"the viewer\"/>"), HasSubstr("is not a name"));
  EXPECT_THAT(ErrorOf("<gaze at=viewer/>"), HasSubstr("not in quotes"));
  EXPECT_THAT(ErrorOf("<gesture intensity=\"1\" name=\"x\"/>"), HasSubstr("unknown attribute 'intensity'"));
  EXPECT_THAT(ErrorOf("</face>"), HasSubstr("a closing tag"));
  EXPECT_THAT(ErrorOf("a < b"), HasSubstr("a '<' that starts no tag at character 3"));
  EXPECT_THAT(ErrorOf("a > b"), HasSubstr("a '>' outside a tag at character 3"));
  EXPECT_THAT(ErrorOf("hel<gaze at=\"viewer\"/>lo"), HasSubstr("a tag inside the word \"hel...\" at character 4"));
  EXPECT_THAT(ErrorOf(std::string("a\0b", 3)), HasSubstr("a control byte 0x00 at character 2"));
  EXPECT_THAT(ErrorOf("a\x1b[31m"), HasSubstr("a control byte 0x1b"));
}

TEST(Markup, RefusesTextOverTheLimits) {
  EXPECT_NO_THROW((void)ParseMarkup(std::string(kMaxSpokenBytes, 'a'), "t"));
  EXPECT_THAT(ErrorOf(std::string(kMaxSpokenBytes + 1, 'a')),
              HasSubstr("the text to speak is over the limit of 500 bytes at character 501"));
  std::string many_tags;
  while (many_tags.size() <= kMaxMarkupBytes) many_tags += "<gaze at=\"viewer\"/> ";
  EXPECT_THAT(ErrorOf(many_tags), HasSubstr("over the limit of 2000"));
}

TEST(Markup, TagsAreTimedAtTheStartOfTheirWord) {
  const MarkedLine line = ParseMarkup(
      "\"Well -- <gesture name=\"Wave\"/>hello, I am 42. <face expr=\"happy\"/>( <gaze at=\"viewer\"/>Bob's pub!",
      "test");
  const SpokenLine spoken = Synthesizer(Voice::kSlt).Synthesize(line.text);
  const std::vector<TimedTag> timed = TimeTags(line, spoken, "test");
  ASSERT_EQ(timed.size(), 3u);
  // "hello": its first phone is hh.
  const auto phone_starting_at = [&](double t) {
    for (const Phone& phone : spoken.phones)
      if (phone.start_s == t) return phone.name;
    return std::string("none");
  };
  EXPECT_EQ(phone_starting_at(timed[0].time_s), "hh");
  // "(" is not spoken: the face tag takes the start of "Bob's", as the gaze does.
  EXPECT_EQ(phone_starting_at(timed[1].time_s), "b");
  EXPECT_EQ(timed[1].time_s, timed[2].time_s);
  EXPECT_LT(timed[0].time_s, timed[1].time_s);
}

// Flite's tokens against the line's words on what people write: abbreviations, numbers,
// symbols, quotes and brackets, punctuation alone, UTF-8, tabs and line breaks.
TEST(Markup, EveryWordFindsFlitesTokenInOrdinaryText) {
  const char* const lines[] = {"U.S.A. is big.",
                               "Send an e-mail at 5:30pm, for $20.",
                               "Dr. Smith... 'quoted' words",
                               "Hello,world and (parens) [x] {y}",
                               "\xc2\xbfQu\xc3\xa9 tal? caf\xc3\xa9",
                               "\"'Nested' quotes,\" she said!!",
                               "a -- b - c ... d ?! e",
                               "x1 2nd 3.14 1,000,000 #tag @you 50%",
                               "it's o'clock ''double'' `tick`",
                               "tab\there\nnewline",
                               "'(hello)' ((x))",
                               "!!! ??? ... ,,,"};
  const Synthesizer synthesizer(Voice::kSlt);
  for (const char* text : lines) {
    const MarkedLine line = ParseMarkup(std::string(text) + " <gaze at=\"viewer\"/>end", "test");
    const SpokenLine spoken = synthesizer.Synthesize(line.text);
    std::vector<TimedTag> timed;
    EXPECT_NO_THROW(timed = TimeTags(line, spoken, "test")) << text;
    ASSERT_EQ(timed.size(), 1u) << text;
    // "end" is the last word: it starts after the leading pause (right after it when nothing
    // before it is spoken) and before the last phone.
    EXPECT_GE(timed[0].time_s, spoken.phones.front().end_s) << text;
    EXPECT_LT(timed[0].time_s, spoken.phones.back().start_s) << text;
  }
}

TEST(Markup, ATagAtTheEndIsTimedAtTheLinesEnd) {
  const MarkedLine line = ParseMarkup("Goodbye. <gesture name=\"Bow\"/>", "test");
  const SpokenLine spoken = Synthesizer(Voice::kSlt).Synthesize(line.text);
  const std::vector<TimedTag> timed = TimeTags(line, spoken, "test");
  ASSERT_EQ(timed.size(), 1u);
  EXPECT_DOUBLE_EQ(timed[0].time_s, spoken.phones.back().end_s);
}

TEST(Markup, AWordTheSynthesizerDidNotReadIsAnErrorNamingIt) {
  const MarkedLine line = ParseMarkup("<gesture name=\"Wave\"/>hello", "scene.yaml, line 9");
  const SpokenLine other = Synthesizer(Voice::kSlt).Synthesize("goodbye");
  try {
    (void)TimeTags(line, other, "scene.yaml, line 9");
    FAIL() << "no error";
  } catch (const SpeechError& error) {
    EXPECT_THAT(error.what(), HasSubstr("scene.yaml, line 9: the word \"hello\" (word 1)"));
  }
}

}  // namespace
}  // namespace arview::speech
