// The markup of a character's lines through speech::ParseMarkup: tags, attributes, quotes, the
// limits, and the words the tags stand before. What it returns must hold together: the text has
// no tag left in it, every tag's word is a word of the text (or the end), every intensity is in
// [0, 1]. Flite is not run here (the tests synthesize real lines).
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>

#include "speech/markup.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string markup(reinterpret_cast<const char*>(data), size);
  try {
    const arview::speech::MarkedLine line = arview::speech::ParseMarkup(markup, "fuzz");
    if (line.text.size() > arview::speech::kMaxSpokenBytes) std::abort();
    if (line.text.find('<') != std::string::npos || line.text.find('>') != std::string::npos) std::abort();
    for (const arview::speech::MarkupTag& tag : line.tags) {
      if (tag.word > line.words.size() || tag.target.empty()) std::abort();
      if (!(tag.intensity >= 0.0 && tag.intensity <= 1.0)) std::abort();
      if (tag.position == 0 || tag.position > markup.size() || markup[tag.position - 1] != '<') std::abort();
    }
  } catch (const arview::speech::SpeechError&) {
  }
  return 0;
}
