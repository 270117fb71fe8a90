// Scene files through authoring::ParseScene (the depth and duplicate-key checks, then yaml-cpp and
// our schema). Assets are not loaded here (fuzz_gltf does that).
#include <exception>
#include <string>

#include "anim_authoring/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)arview::authoring::ParseScene(text, "fuzz-scene.yaml");
  } catch (const std::exception&) {
  }
  return 0;
}
