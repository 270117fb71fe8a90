#include "dialogue/pattern.h"

#include <functional>

#include "dialogue/emotion.h"  // DialogueError

namespace arview::dialogue {
namespace {

bool IsWordByte(char c) {
  const auto byte = static_cast<unsigned char>(c);
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '\'' || byte >= 0x80;
}

// What a pattern's words may hold: what the recogniser's dictionary spells words with
// (listen/grammar.h: ASCII letters and apostrophes, numbers spelled out).
bool IsPatternLetter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '\''; }

char Lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

std::string Shown(char c) {
  const auto byte = static_cast<unsigned char>(c);
  if (byte < 0x20 || byte == 0x7f) {
    static const char* hex = "0123456789abcdef";
    return std::string("\\x") + hex[byte >> 4] + hex[byte & 15];
  }
  return std::string("'") + c + "'";
}

}  // namespace

std::vector<std::string> HeardWords(std::string_view heard) {
  std::vector<std::string> words;
  std::string word;
  for (const char c : heard.substr(0, kMaxHeardBytes)) {
    if (IsWordByte(c)) {
      word += Lower(c);
    } else if (!word.empty()) {
      words.push_back(std::move(word));
      word.clear();
    }
  }
  if (!word.empty()) words.push_back(std::move(word));
  return words;
}

Pattern Pattern::Compile(std::string_view text, const std::string& origin) {
  auto fail = [&](const std::string& why) -> Pattern {
    throw DialogueError(origin + ": pattern '" + std::string(text.substr(0, 200)) + "' cannot compile: " + why);
  };
  Pattern p;
  std::string word;
  auto end_word = [&] {
    if (word.empty()) return;
    p.tokens_.push_back(std::move(word));
    word.clear();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const std::string at = " at character " + std::to_string(i + 1);
    if (c == ' ' || c == '\t') {
      end_word();
    } else if (c == '*') {
      if (!word.empty() || (i + 1 < text.size() && IsWordByte(text[i + 1])))
        return fail("a '*' inside a word" + at + " (a wildcard stands for whole words)");
      if (!p.tokens_.empty() && p.tokens_.back() == "*")
        return fail("two wildcards side by side" + at + " (which words each takes would be a guess)");
      p.tokens_.push_back("*");
      if (++p.wildcards_ > kMaxWildcards) return fail("more than " + std::to_string(kMaxWildcards) + " wildcards");
    } else if (IsPatternLetter(c)) {
      word += Lower(c);
    } else if (c >= '0' && c <= '9') {
      return fail(Shown(c) + at + ": numbers are spelled out ('ten', not '10'), as the recogniser's dictionary has them");
    } else {
      return fail(Shown(c) + at + " is not a letter a-z, an apostrophe, a space or '*'");
    }
  }
  end_word();
  if (p.tokens_.size() > kMaxPatternTokens)
    return fail(std::to_string(p.tokens_.size()) + " words and wildcards, more than " + std::to_string(kMaxPatternTokens));
  if (p.tokens_.empty()) return fail("it has no word and no wildcard");
  for (std::size_t i = 0; i < p.tokens_.size(); ++i) p.text_ += (i ? " " : "") + p.tokens_[i];
  return p;
}

std::optional<std::vector<std::string>> Pattern::Match(std::string_view heard) const {
  const std::vector<std::string> words = HeardWords(heard);
  const std::size_t n = words.size();
  // failed[t * (n + 1) + w]: token t cannot match from word w on (memoised, so a pattern of k
  // wildcards costs O(tokens · words²) at worst, never exponential).
  std::vector<char> failed(tokens_.size() * (n + 1), 0);
  std::vector<std::string> captures;
  std::function<bool(std::size_t, std::size_t)> match = [&](std::size_t t, std::size_t w) -> bool {
    if (t == tokens_.size()) return w == n;
    char& known_failed = failed[t * (n + 1) + w];
    if (known_failed) return false;
    if (tokens_[t] != "*") {
      if (w < n && words[w] == tokens_[t] && match(t + 1, w + 1)) return true;
    } else {
      for (std::size_t end = w + 1; end <= n; ++end) {
        if (!match(t + 1, end)) continue;
        std::string captured;
        for (std::size_t k = w; k < end; ++k) captured += (k > w ? " " : "") + words[k];
        captures.push_back(std::move(captured));
        return true;
      }
    }
    known_failed = 1;
    return false;
  };
  if (!match(0, 0)) return std::nullopt;
  // Captures were pushed as the recursion unwound: last wildcard first.
  return std::vector<std::string>(captures.rbegin(), captures.rend());
}

}  // namespace arview::dialogue
