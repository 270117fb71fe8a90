#include "listen/grammar.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "listen/listen_error.h"

namespace arview::listen {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::vector<std::string>& patterns, const std::vector<std::string>& vocabulary = {"x"}) {
  try {
    JsgfFromPatterns(patterns, vocabulary);
  } catch (const ListenError& error) {
    return error.what();
  }
  return "";
}

TEST(Grammar, PatternsAreLowercaseWordsAndStandaloneWildcards) {
  EXPECT_EQ(PatternTokens("  Hello my NAME\tis *  "), (std::vector<std::string>{"hello", "my", "name", "is", "*"}));
  EXPECT_EQ(PatternTokens("don't * *"), (std::vector<std::string>{"don't", "*", "*"}));
}

TEST(Grammar, PatternsBecomeTheAlternativesOfOnePublicRule) {
  const std::string jsgf = JsgfFromPatterns({"hello there", "Goodbye"}, {});
  EXPECT_EQ(jsgf, "#JSGF V1.0;\ngrammar arview;\npublic <heard> = (hello there) | (goodbye);\n");
}

TEST(Grammar, AWildcardStandsForOneToThreeVocabularyWords) {
  const std::string jsgf = JsgfFromPatterns({"my name is *"}, {"anna", "Bob"});
  EXPECT_THAT(jsgf, HasSubstr("public <heard> = (my name is <wildcard>);\n"));
  EXPECT_THAT(jsgf, HasSubstr("<wildcard> = <any> [<any>] [<any>];\n"));
  EXPECT_THAT(jsgf, HasSubstr("<any> = anna | bob;\n"));
}

TEST(Grammar, WithoutAWildcardTheVocabularyIsLeftOut) {
  EXPECT_THAT(JsgfFromPatterns({"yes"}, {"anna"}), ::testing::Not(HasSubstr("<any>")));
}

TEST(Grammar, BadPatternsAreOneLineNamingThem) {
  EXPECT_EQ(ErrorOf({}), "listen: no patterns to listen for: a grammar needs at least one");
  EXPECT_EQ(ErrorOf({"yes", "  "}), "listen: the pattern \"  \" is empty: a pattern needs at least one word or '*'");
  EXPECT_EQ(ErrorOf({"go*"}), "listen: the pattern \"go*\" has a '*' inside a word: a wildcard stands alone between spaces");
  EXPECT_EQ(ErrorOf({"*go"}), "listen: the pattern \"*go\" has a '*' inside a word: a wildcard stands alone between spaces");
  EXPECT_EQ(ErrorOf({"hello!"}),
            "listen: the pattern \"hello!\" has the character '!': a pattern holds words (letters and apostrophes, "
            "numbers spelled out) and '*'");
  EXPECT_EQ(ErrorOf({"go 10 metres"}).substr(0, 50), "listen: the pattern \"go 10 metres\" has the charact");
  EXPECT_EQ(ErrorOf({"call me *"}, {}), "listen: the pattern \"call me *\" has a '*' but the wildcard vocabulary is empty");
  EXPECT_EQ(ErrorOf({"call me *"}, {"two words"}),
            "listen: the wildcard vocabulary's entry \"two words\" is not one word");
}

}  // namespace
}  // namespace arview::listen
