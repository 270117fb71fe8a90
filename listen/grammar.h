#pragma once
// The phrases the dialogue can hear next, as a JSGF grammar for PocketSphinx.
//
// A pattern is words separated by spaces (letters and apostrophes, numbers spelled out; matched
// without regard to case) and `*`. A grammar cannot say "any word": PocketSphinx's grammar search
// knows only the words it is given. So `*` stands for one to kMaxWildcardWords words of a
// wildcard vocabulary (RecognizerOptions::wildcard_words, or by default the most probable words
// of the model's language model: docs/listen.md, "Patterns"). An utterance must match a whole
// pattern; words before or after it are not skipped.

#include <cstddef>
#include <string>
#include <vector>

namespace arview::listen {

// How many words one `*` may stand for. Three covers a name ("hello my name is *": "anna",
// "mary jane", "jean luc picard") without letting a wildcard swallow a whole sentence.
inline constexpr std::size_t kMaxWildcardWords = 3;

// The pattern's tokens, lowercased: words and "*". Throws ListenError naming the pattern when
// it is empty, or holds a character other than letters, apostrophes, spaces and `*`,
// or a `*` inside a word ("go*").
std::vector<std::string> PatternTokens(const std::string& pattern);

// The JSGF grammar (public rule <heard>) that accepts exactly the patterns. Throws ListenError
// when there are no patterns, a pattern is bad (PatternTokens), or a pattern has a `*` and
// `wildcard_words` is empty. Words are not checked against a dictionary here: the decoder does
// that when it compiles the grammar.
std::string JsgfFromPatterns(const std::vector<std::string>& patterns,
                             const std::vector<std::string>& wildcard_words);

}  // namespace arview::listen
