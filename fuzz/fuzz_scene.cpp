// Scene files through authoring::ParseScene (the depth and duplicate-key checks, then yaml-cpp and
// our schema), then each character's `lines:` through speech::ParseMarkup, as the session reads
// them before it synthesizes anything. What is accepted must hold together: at most
// kMaxLinesPerCharacter lines, each with a line number and, for `when: near`, far beyond near.
// Assets are not loaded here (fuzz_gltf does that), nor Flite run (the tests synthesize lines).
#include <cmath>
#include <cstdlib>
#include <exception>
#include <string>

#include "anim_authoring/scene.h"
#include "speech/markup.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  arview::authoring::Scene scene;
  try {
    scene = arview::authoring::ParseScene(text, "fuzz-scene.yaml");
  } catch (const std::exception&) {
    return 0;
  }
  for (const arview::authoring::CharacterSpec& c : scene.characters) {
    if (c.lines.size() > arview::authoring::kMaxLinesPerCharacter) std::abort();
    for (const arview::authoring::LineSpec& l : c.lines) {
      if (l.line <= 0 || l.say.empty()) std::abort();
      if (!(l.far > l.near) || !std::isfinite(l.far) || !(l.near >= 0)) std::abort();
      try {
        (void)arview::speech::ParseMarkup(l.say, "fuzz-scene.yaml:" + std::to_string(l.line));
      } catch (const arview::speech::SpeechError&) {
      }
    }
  }
  return 0;
}
