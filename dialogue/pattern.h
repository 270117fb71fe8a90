#pragma once
// What the character can hear: patterns of words with `*` wildcards (ALICE's, as the thesis's
// input_match "hello my name is *"). A `*` stands for one or more words and captures them
// ($1, $2, ... in order). Matching is on words: the heard text is lower-cased and split at
// anything that is not a letter, a digit or an apostrophe, so "Hello, my name is Ann!" matches.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arview::dialogue {

// At most nine wildcards: captures are written $1 to $9.
inline constexpr std::size_t kMaxWildcards = 9;
// The most words and wildcards one pattern may hold (a spoken phrase is far shorter); bounds the
// matcher's table (tokens × heard words).
inline constexpr std::size_t kMaxPatternTokens = 64;
// The longest heard text matched, in bytes (a minute of speech is far less).
inline constexpr std::size_t kMaxHeardBytes = 4096;

class Pattern {
 public:
  // Throws DialogueError("<origin>: pattern '<text>' cannot compile: <why>") for an empty
  // pattern, a character other than ASCII letters, apostrophes, spaces and '*' (numbers are
  // spelled out, as the recogniser's grammar needs: listen/grammar.h), a '*' inside a
  // word, two wildcards side by side (their split would be a guess), more than nine wildcards, or more
  // than kMaxPatternTokens words and wildcards.
  static Pattern Compile(std::string_view text, const std::string& origin);

  const std::string& text() const { return text_; }  // as compiled: lower case, single spaces
  std::size_t wildcards() const { return wildcards_; }

  // The captured words of each wildcard (joined by single spaces) when `heard` matches, each
  // wildcard taking as few words as it can from the left; nothing when it does not match.
  std::optional<std::vector<std::string>> Match(std::string_view heard) const;

 private:
  std::string text_;
  std::vector<std::string> tokens_;  // words and "*"
  std::size_t wildcards_ = 0;
};

// The words of a heard text as patterns see them (lower case; letters, digits, apostrophes).
// Bytes from 0x80 up count as letters (UTF-8), lower-cased only in ASCII.
std::vector<std::string> HeardWords(std::string_view heard);

}  // namespace arview::dialogue
