#include "listen/grammar.h"

#include <cctype>
#include <sstream>

#include "listen/listen_error.h"

namespace arview::listen {
namespace {

bool IsWordCharacter(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '\'';
}

[[noreturn]] void RefusePattern(const std::string& pattern, const std::string& why) {
  throw ListenError("listen: the pattern \"" + pattern + "\" " + why);
}

// One alternative of the public rule: the pattern's words, each `*` as <wildcard>.
std::string RuleBody(const std::vector<std::string>& tokens) {
  std::string body;
  for (const std::string& token : tokens) {
    if (!body.empty()) body += ' ';
    body += token == "*" ? "<wildcard>" : token;
  }
  return body;
}

}  // namespace

std::vector<std::string> PatternTokens(const std::string& pattern) {
  std::vector<std::string> tokens;
  std::string word;
  const auto end_word = [&] {
    if (!word.empty()) tokens.push_back(std::move(word));
    word.clear();
  };
  char previous = ' ';
  for (const char c : pattern) {
    const bool wildcard_touches_word = (c == '*' && !word.empty()) || (previous == '*' && IsWordCharacter(c));
    if (wildcard_touches_word) {
      RefusePattern(pattern, "has a '*' inside a word: a wildcard stands alone between spaces");
    }
    if (c == ' ' || c == '\t') {
      end_word();
    } else if (c == '*') {
      tokens.emplace_back("*");
    } else if (IsWordCharacter(c)) {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else {
      std::ostringstream what;
      what << "has the character '" << c << "': a pattern holds words (letters and apostrophes, numbers spelled out) and '*'";
      RefusePattern(pattern, what.str());
    }
    previous = c;
  }
  end_word();
  if (tokens.empty()) RefusePattern(pattern, "is empty: a pattern needs at least one word or '*'");
  return tokens;
}

std::string JsgfFromPatterns(const std::vector<std::string>& patterns,
                             const std::vector<std::string>& wildcard_words) {
  if (patterns.empty()) throw ListenError("listen: no patterns to listen for: a grammar needs at least one");
  std::vector<std::string> alternatives;
  bool has_wildcard = false;
  for (const std::string& pattern : patterns) {
    const std::vector<std::string> tokens = PatternTokens(pattern);
    for (const std::string& token : tokens) {
      if (token == "*") has_wildcard = true;
    }
    if (has_wildcard && wildcard_words.empty()) {
      RefusePattern(pattern, "has a '*' but the wildcard vocabulary is empty");
    }
    alternatives.push_back(RuleBody(tokens));
  }
  std::string jsgf = "#JSGF V1.0;\ngrammar arview;\npublic <heard> = ";
  for (std::size_t i = 0; i < alternatives.size(); ++i) {
    jsgf += (i == 0 ? "(" : " | (") + alternatives[i] + ")";
  }
  jsgf += ";\n";
  if (has_wildcard) {
    jsgf += "<wildcard> = <any>";
    for (std::size_t i = 1; i < kMaxWildcardWords; ++i) jsgf += " [<any>]";
    jsgf += ";\n<any> = ";
    for (std::size_t i = 0; i < wildcard_words.size(); ++i) {
      const std::vector<std::string> word = PatternTokens(wildcard_words[i]);
      if (word.size() != 1 || word[0] == "*") {
        throw ListenError("listen: the wildcard vocabulary's entry \"" + wildcard_words[i] + "\" is not one word");
      }
      jsgf += (i == 0 ? "" : " | ") + word[0];
    }
    jsgf += ";\n";
  }
  return jsgf;
}

}  // namespace arview::listen
