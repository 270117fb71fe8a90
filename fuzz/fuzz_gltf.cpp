// Asset loading through authoring::LoadCharacter: the glTF structure check (anim_authoring/gltf_check.h),
// then Assimp's glTF/GLB importers, then our import of
// skeleton, skin, materials, morph targets and clips. Assimp is Debian's build (not instrumented): a crash
// inside it still stops the fuzzer (SEGV, ASan on our side of the calls), but its coverage
// is not seen; the coverage figure is our importer's.
//
// Besides the shared data's RiggedSimple.glb, LLVMFuzzerInitialize writes morph-target seeds made
// here (a quad with two named targets and a weight animation, self-contained through a data:
// URI buffer): as it is, with a target of another vertex count, a non-finite delta, weights keyed
// for three targets of a mesh with two, and weights on a node whose mesh has none.
#include <nlohmann/json.hpp>

#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "anim_authoring/import.h"
#include "fuzz/fuzz_support.h"

namespace {

std::string Base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<std::uint8_t>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// A buffer built view by view: each call appends floats (or shorts) and returns its accessor.
struct BufferBuilder {
  std::string bytes;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();

  int Add(const std::vector<float>& values, const char* type, int components) {
    return Append(values.data(), values.size() * sizeof(float), 5126, type, static_cast<int>(values.size()) / components);
  }
  int AddIndices(const std::vector<std::uint16_t>& values) {
    return Append(values.data(), values.size() * sizeof(std::uint16_t), 5123, "SCALAR", static_cast<int>(values.size()));
  }
  int Append(const void* data, std::size_t size, int component_type, const char* type, int count) {
    while (bytes.size() % 4) bytes.push_back('\0');
    views.push_back({{"buffer", 0}, {"byteOffset", bytes.size()}, {"byteLength", size}});
    bytes.append(static_cast<const char*>(data), size);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", component_type}, {"count", count}, {"type", type}});
    return static_cast<int>(accessors.size()) - 1;
  }
};

enum class MorphSeed { kValid, kShortTarget, kNonFiniteDelta, kWeightsForAMissingTarget, kWeightsWithoutTargets };

std::string MorphQuad(MorphSeed seed) {
  BufferBuilder b;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int position = b.Add({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3", 3);
  b.accessors[position]["min"] = {0, 0, 0};
  b.accessors[position]["max"] = {1, 1, 0};
  const int normal = b.Add({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
  const int indices = b.AddIndices({0, 1, 2, 0, 2, 3});
  const int smile = seed == MorphSeed::kShortTarget ? b.Add({0, 0, 0, 0, 0, 0, 0, 0.2f, 0}, "VEC3", 3)
                                                    : b.Add({0, 0, 0, 0, 0, 0, 0, 0.2f, 0, 0, 0.2f, 0}, "VEC3", 3);
  const int smile_normal = b.Add({0, 0, 0, 0, 0, 0, 0, 0.1f, 0, 0, 0.1f, 0}, "VEC3", 3);
  const int blink = b.Add({0.3f, 0, 0, 0, 0, seed == MorphSeed::kNonFiniteDelta ? nan : 0.f, 0, 0, 0, 0, 0, 0.1f}, "VEC3", 3);
  const int times = b.Add({0, 0.5f, 1}, "SCALAR", 1);
  b.accessors[times]["min"] = {0};
  b.accessors[times]["max"] = {1};
  const int targets_keyed = seed == MorphSeed::kWeightsForAMissingTarget ? 3 : 2;
  std::vector<float> weights;
  for (int k = 0; k < 3; ++k)
    for (int t = 0; t < targets_keyed; ++t) weights.push_back(0.5f * static_cast<float>((k + t) % 3));
  const int weight_values = b.Add(weights, "SCALAR", 1);

  nlohmann::json primitive = {{"attributes", {{"POSITION", position}, {"NORMAL", normal}}}, {"indices", indices}};
  nlohmann::json mesh = {{"name", "face"}};
  if (seed != MorphSeed::kWeightsWithoutTargets) {
    primitive["targets"] = {{{"POSITION", smile}, {"NORMAL", smile_normal}}, {{"POSITION", blink}}};
    mesh["weights"] = {0, 0};
    mesh["extras"] = {{"targetNames", {"mouthSmile", "eyeBlinkLeft"}}};
  }
  mesh["primitives"] = {primitive};
  nlohmann::json doc = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"name", "head"}, {"mesh", 0}}}},
      {"meshes", {mesh}},
      {"animations",
       {{{"name", "talk"},
         {"samplers", {{{"input", times}, {"output", weight_values}, {"interpolation", "LINEAR"}}}},
         {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}}}}}},
      {"accessors", b.accessors},
      {"bufferViews", b.views},
      {"buffers", {{{"byteLength", b.bytes.size()}, {"uri", "data:application/octet-stream;base64," + Base64(b.bytes)}}}}};
  return doc.dump();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (seeds.empty()) return 0;
  const std::pair<MorphSeed, const char*> kinds[] = {{MorphSeed::kValid, "morph_quad.gltf"},
                                                     {MorphSeed::kShortTarget, "morph_short_target.gltf"},
                                                     {MorphSeed::kNonFiniteDelta, "morph_nan_delta.gltf"},
                                                     {MorphSeed::kWeightsForAMissingTarget, "morph_missing_target.gltf"},
                                                     {MorphSeed::kWeightsWithoutTargets, "morph_no_targets.gltf"}};
  for (const auto& [kind, name] : kinds) arview::fuzz::WriteBytes(seeds / name, MorphQuad(kind));
  return 0;
}

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
