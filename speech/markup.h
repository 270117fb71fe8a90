#pragma once
// The markup of what a character says (docs/speech.md, "Markup"): self-closing tags in the text
//   <gesture name="Wave"/>  <face expr="happy" intensity="0.6"/>  <gaze at="viewer"/>
// each standing before a word. ParseMarkup takes the tags out, giving the text to synthesize and
// each tag with the index of its word; TimeTags gives each tag the time its word starts.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "base/enum_table.h"
#include "speech/synthesizer.h"

namespace arview::speech {

// The longest text a line may speak, in bytes once the tags are out (about 35 s of speech), and
// the longest markup, tags included.
inline constexpr std::size_t kMaxSpokenBytes = 500;
inline constexpr std::size_t kMaxMarkupBytes = 2000;

enum class TagKind { kGesture, kFace, kGaze };
constexpr auto EnumNames(TagKind) {
  return EnumTable<TagKind, 3>{{{TagKind::kGesture, "gesture"}, {TagKind::kFace, "face"}, {TagKind::kGaze, "gaze"}}};
}

struct MarkupTag {
  TagKind kind = TagKind::kGesture;
  std::string target;      // the gesture's name, the expression, or what the gaze is at
  double intensity = 1.0;  // <face>'s intensity in [0,1]; 1 when not given and for the others
  std::size_t word = 0;    // the index of the word the tag stands before; words.size() at the end
  std::size_t position = 0;  // the tag's '<' in the markup, 1-based characters (bytes)
};

struct MarkedLine {
  std::string text;                // what to synthesize: the markup with the tags taken out
  std::vector<std::string> words;  // text split at spaces, tabs and line breaks (as Flite splits)
  std::vector<MarkupTag> tags;     // in text order
};

// `origin` names where the markup comes from in messages ("scene.yaml, line 3"). A SpeechError
// names it, the problem and the character where it is: an unknown tag or attribute, a tag not
// closed with "/>", a missing or repeated attribute, a value that is not a name, an intensity
// outside [0,1], a tag inside a word, a stray '>', a control byte, a line over the limits.
MarkedLine ParseMarkup(std::string_view markup, std::string_view origin);

struct TimedTag {
  MarkupTag tag;
  double time_s = 0;  // when its word's first phone starts; the line's end for a tag at the end
};

// Each tag at the start of its word, matching the line's words to the tokens Flite read. A word
// Flite says nothing for ("--") takes the next spoken word's start. A SpeechError (naming
// `origin`) when a word cannot be found among Flite's tokens.
std::vector<TimedTag> TimeTags(const MarkedLine& line, const SpokenLine& spoken, std::string_view origin);

}  // namespace arview::speech
