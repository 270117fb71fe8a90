// Asset loading through authoring::LoadCharacter: the glTF structure check (anim_authoring/gltf_check.h),
// then Assimp's glTF/GLB importers, then our import of
// skeleton, skin, materials and clips. Assimp is Debian's build (not instrumented): a crash
// inside it still stops the fuzzer (SEGV, ASan on our side of the calls), but its coverage
// is not seen; the coverage figure is our importer's.
#include <exception>

#include "anim_authoring/import.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The extension picks Assimp's importer; binary glTF checks its magic and falls back to
  // reading JSON glTF, so both forms are reached through one name.
  const auto file = arview::fuzz::WriteInput("asset.glb", data, size);
  try {
    (void)arview::authoring::LoadCharacter(file);
  } catch (const std::exception&) {
  }
  return 0;
}
