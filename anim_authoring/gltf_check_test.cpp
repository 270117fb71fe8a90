// The glTF structure checks before Assimp (issue 17: fuzz_gltf's SEGV inside libassimp).
#include "anim_authoring/gltf_check.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "anim/character.h"
#include "anim_authoring/import.h"
#include "tests/support/test_data.h"

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// One folder per test process, removed when the process ends.
fs::path TempFolder() {
  struct Folder {
    fs::path path = fs::temp_directory_path() / ("arview_gltf_check_" + std::to_string(::getpid()));
    Folder() { fs::create_directories(path); }
    ~Folder() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Folder folder;
  return folder.path;
}

template <typename T>
void Append(std::string& bytes, const T& value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// A skinned triangle: node 0 draws mesh 0 with skin 0, whose joints are nodes 1 (root) and 2.
// Accessors: 0 POSITION (3 VEC3 floats), 1 JOINTS_0 (3 VEC4 bytes), 2 WEIGHTS_0 (3 VEC4 floats),
// 3 inverse bind matrices (2 MAT4 floats), 4 indices (3 unsigned shorts).
struct TinySkinnedGltf {
  json doc;
  std::string bin;

  TinySkinnedGltf() {
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) Append(bin, v);           // 0..36
    for (std::uint8_t j : {0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0}) Append(bin, j);              // 36..48
    for (float w : {1.f, 0.f, 0.f, 0.f, 0.5f, 0.5f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f}) Append(bin, w);  // 48..96
    for (int m = 0; m < 2; ++m)
      for (int k = 0; k < 16; ++k) Append(bin, k % 5 == 0 ? 1.f : 0.f);                     // 96..224
    for (std::uint16_t i : {0, 1, 2, 0}) Append(bin, i);                                     // 224..232 (padded)
    doc = json::parse(R"({
      "asset": {"version": "2.0"},
      "scene": 0,
      "scenes": [{"nodes": [0, 1]}],
      "nodes": [{"name": "body", "mesh": 0, "skin": 0},
                {"name": "root", "children": [2]},
                {"name": "bone", "translation": [0, 1, 0]}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}, "indices": 4}]}],
      "skins": [{"joints": [1, 2], "inverseBindMatrices": 3}],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
        {"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC4"},
        {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"},
        {"bufferView": 3, "componentType": 5126, "count": 2, "type": "MAT4"},
        {"bufferView": 4, "componentType": 5123, "count": 3, "type": "SCALAR"}],
      "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 36},
        {"buffer": 0, "byteOffset": 36, "byteLength": 12},
        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
        {"buffer": 0, "byteOffset": 96, "byteLength": 128},
        {"buffer": 0, "byteOffset": 224, "byteLength": 6}],
      "buffers": [{"byteLength": 232}]
    })");
  }

  // The GLB container: header, JSON chunk (space-padded), BIN chunk.
  std::string Glb() const {
    std::string text = doc.dump();
    while (text.size() % 4) text += ' ';
    std::string out;
    Append(out, std::uint32_t{0x46546C67});
    Append(out, std::uint32_t{2});
    Append(out, static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
    Append(out, static_cast<std::uint32_t>(text.size()));
    Append(out, std::uint32_t{0x4E4F534A});
    out += text;
    Append(out, static_cast<std::uint32_t>(bin.size()));
    Append(out, std::uint32_t{0x004E4942});
    out += bin;
    return out;
  }
};

fs::path Write(const std::string& name, const std::string& bytes) {
  const fs::path file = TempFolder() / name;
  std::ofstream(file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return file;
}

// The error CheckGltfStructure throws for `bytes`, or "" when it accepts them.
std::string CheckError(const std::string& bytes, const std::string& name = "asset.glb") {
  const fs::path file = Write(name, bytes);
  try {
    CheckGltfStructure(file);
    return "";
  } catch (const anim::Error& e) {
    return e.what();
  }
}

std::string CheckError(const std::function<void(TinySkinnedGltf&)>& mutate) {
  TinySkinnedGltf gltf;
  mutate(gltf);
  return CheckError(gltf.Glb());
}

#define EXPECT_REFUSED(error, text)                                                    \
  do {                                                                                 \
    const std::string e_ = (error);                                                    \
    EXPECT_EQ(e_.rfind(TempFolder().string(), 0), 0u) << "not naming the file: " << e_; \
    EXPECT_NE(e_.find(text), std::string::npos) << "expected '" << (text) << "' in: " << e_; \
  } while (0)

TEST(GltfCheck, TheTinySkinnedTriangleIsAcceptedAndLoads) {
  const fs::path file = Write("asset.glb", TinySkinnedGltf().Glb());
  EXPECT_NO_THROW(CheckGltfStructure(file));
  const anim::Character c = LoadCharacter(file);
  EXPECT_EQ(c.skeleton.size(), 2);
  ASSERT_EQ(c.meshes.size(), 1u);
  EXPECT_EQ(c.meshes[0].vertex_count(), 3);
}

// fuzz_gltf's crash: Debian's Assimp 5.2.5 reads a null pointer on a skin without
// inverseBindMatrices (RiggedSimple.glb with that key's name garbled). The tiny file below crashed
// `arview anim info` with SIGSEGV before the check; now it is one line.
TEST(GltfCheck, ASkinWithoutInverseBindMatricesIsRefusedBeforeAssimp) {
  TinySkinnedGltf gltf;
  gltf.doc["skins"][0].erase("inverseBindMatrices");
  const fs::path file = Write("asset.glb", gltf.Glb());
  try {
    (void)LoadCharacter(file);
    FAIL() << "loaded";
  } catch (const anim::Error& e) {
    EXPECT_REFUSED(e.what(), "skins[0] has no inverseBindMatrices");
  }
}

TEST(GltfCheck, TheGlbHeaderAndChunkLengthsAreCheckedAgainstTheFile) {
  const std::string good = TinySkinnedGltf().Glb();
  auto with_u32 = [&](std::size_t at, std::uint32_t v) {
    std::string b = good;
    std::memcpy(b.data() + at, &v, 4);
    return b;
  };
  const std::uint32_t json_length = [&] {
    std::uint32_t v;
    std::memcpy(&v, good.data() + 12, 4);
    return v;
  }();
  const std::size_t bin_header = 20 + json_length;
  EXPECT_REFUSED(CheckError(with_u32(4, 1)), "GLB version 1 is not 2");
  EXPECT_REFUSED(CheckError(with_u32(8, good.size() + 100)), "the GLB header gives a length of");
  EXPECT_REFUSED(CheckError(with_u32(12, 0x7fffffff)), "GLB chunk 0 at byte 12 says 2147483647 bytes");
  EXPECT_REFUSED(CheckError(with_u32(12, json_length - 2)), "is not a multiple of 4");
  EXPECT_REFUSED(CheckError(with_u32(16, 0x004E4942)), "the first GLB chunk is not JSON");
  EXPECT_REFUSED(CheckError(with_u32(bin_header, 4096)), "GLB chunk 1 at byte");
  // Cut anywhere: the header's length no longer matches (or nothing is left of the header).
  for (std::size_t cut : {std::size_t{3}, std::size_t{12}, std::size_t{19}, good.size() / 2, good.size() - 1}) {
    std::string b = good.substr(0, cut);
    if (cut >= 12) std::memcpy(b.data() + 8, &cut, 4);  // even with the length mended
    EXPECT_NE(CheckError(b), "") << "cut at " << cut;
  }
  // The BIN chunk shorter than the buffer it holds.
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.bin.resize(200); }),
                 "buffers[0].byteLength 232 is larger than the GLB's BIN chunk (200 bytes)");
}

TEST(GltfCheck, TheJsonChunkMustParseAsUtf8WithinTheDepthLimit) {
  std::string garbled = TinySkinnedGltf().Glb();
  const std::size_t at = garbled.find("inverseBindMatrices");
  ASSERT_NE(at, std::string::npos);
  garbled[at + 9] = '\x92';  // fuzz_gltf's mutation: bytes of a key replaced by ones that are not UTF-8
  EXPECT_REFUSED(CheckError(garbled), "the glTF JSON does not parse");
  std::string deep = "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + std::string(200, '[') + std::string(200, ']') + "}";
  EXPECT_REFUSED(CheckError(deep, "asset.gltf"), "nested deeper than 64 levels");
  EXPECT_REFUSED(CheckError(R"({"asset": {"version": "1.0"}})", "asset.gltf"),
                 "glTF version '1.0' is not supported");
}

TEST(GltfCheck, IndicesOutsideTheirArraysAreRefusedNamingTheField) {
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][0]["bufferView"] = 9; }),
                 "accessors[0].bufferView = 9 is outside 'bufferViews' (5 entries)");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 17; }),
                 "meshes[0].primitives[0].attributes.POSITION = 17 is outside 'accessors'");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["skins"][0]["joints"][1] = 3; }),
                 "skins[0].joints[1] is not an index into 'nodes'");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["nodes"][0]["skin"] = -1; }),
                 "nodes[0].skin is not a non-negative integer");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["scene"] = 1; }), "the file.scene = 1 is outside 'scenes'");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][4]["componentType"] = 5124; }),
                 "accessors[4].componentType 5124 is not a glTF component type");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][4]["type"] = "VEC5"; }),
                 "accessors[4].type 'VEC5' is not a glTF accessor type");
}

TEST(GltfCheck, ByteRangesOutsideWhatHoldsThemAreRefused) {
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["bufferViews"][3]["byteLength"] = 200; }),
                 "bufferViews[3] (bytes 96-296) runs past the end of buffers[0] (232 bytes)");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][0]["count"] = 4; }),
                 "accessors[0]: 4 elements from byte 0 need 48 bytes, bufferViews[0] has 36");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][0]["byteOffset"] = 4; }),
                 "accessors[0]: 3 elements from byte 4 need 40 bytes");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["bufferViews"][0]["byteStride"] = 8; }),
                 "byteStride 8 is smaller than one element (12 bytes)");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][1]["count"] = 2; }),
                 "meshes[0].primitives[0].attributes.JOINTS_0 has 2 elements, POSITION has 3");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["accessors"][3]["count"] = 1; }),
                 "skins[0].inverseBindMatrices has 1 matrices for 2 joints");
}

TEST(GltfCheck, ValuesThatIndexFurtherAreReadAndChecked) {
  // A joint index past the skin's two joints, a vertex index past the three vertices.
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.bin[36 + 4 * 2 + 1] = 5; }),
                 "JOINTS_0: element 2 holds 5, not below the joint count 2 of skins[0]");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.bin[224 + 2] = 3; }),
                 "meshes[0].primitives[0].indices (accessors[4]): element 1 holds 3, not below the vertex count 3");
}

TEST(GltfCheck, TheNodeGraphMustBeAForest) {
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["nodes"][2]["children"] = {1}; }),
                 "is in a cycle of children");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["nodes"][0]["children"] = {2}; }),
                 "nodes[2] is a child of both nodes[0] and nodes[1]");
  EXPECT_REFUSED(CheckError([](TinySkinnedGltf& g) { g.doc["nodes"][1]["children"] = {1}; }),
                 "nodes[1].children[0] is the node itself");
}

TEST(GltfCheck, AnimationOutputsCoverTheirKeyTimes) {
  auto with_animation = [](int output_count) {
    return [output_count](TinySkinnedGltf& g) {
      for (float t : {0.f, 1.f}) Append(g.bin, t);
      for (int k = 0; k < 8; ++k) Append(g.bin, k == 3 || k == 7 ? 1.f : 0.f);
      g.doc["buffers"][0]["byteLength"] = g.bin.size();
      g.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 232}, {"byteLength", 8}});
      g.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 240}, {"byteLength", 32}});
      g.doc["accessors"].push_back({{"bufferView", 5}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}});
      g.doc["accessors"].push_back({{"bufferView", 6}, {"componentType", 5126}, {"count", output_count}, {"type", "VEC4"}});
      g.doc["animations"] = json::parse(R"([{"samplers": [{"input": 5, "output": 6}],
                                             "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}]}])");
    };
  };
  EXPECT_EQ(CheckError(with_animation(2)), "");
  EXPECT_REFUSED(CheckError(with_animation(1)), "animations[0].channels[0]: 1 output values for 2 key times");
}

TEST(GltfCheck, ExternalBuffersStayInsideTheAssetsFolderAndHoldTheirLength) {
  TinySkinnedGltf gltf;
  const fs::path folder = TempFolder() / "external";
  fs::create_directories(folder);
  std::ofstream(folder / "tri.bin", std::ios::binary).write(gltf.bin.data(), static_cast<std::streamsize>(gltf.bin.size()));
  gltf.doc["buffers"][0]["uri"] = "tri.bin";
  const fs::path file = folder / "asset.gltf";
  std::ofstream(file) << gltf.doc.dump();
  EXPECT_NO_THROW(CheckGltfStructure(file));
  EXPECT_EQ(LoadCharacter(file).meshes.size(), 1u);

  auto error_with_uri = [&](const std::string& uri) {
    gltf.doc["buffers"][0]["uri"] = uri;
    std::ofstream(file) << gltf.doc.dump();
    try {
      CheckGltfStructure(file);
      return std::string();
    } catch (const anim::Error& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(error_with_uri("../../../../etc/passwd").find("buffers[0].uri"), std::string::npos);
  EXPECT_NE(error_with_uri("missing.bin").find("buffers[0].uri"), std::string::npos);
  std::ofstream(folder / "short.bin", std::ios::binary) << "abc";
  EXPECT_NE(error_with_uri("short.bin").find("buffers[0].byteLength 232 is larger than"), std::string::npos);
  EXPECT_NE(error_with_uri("data:application/octet-stream;base64,AAAA").find("larger than its data: URI (3 bytes)"),
            std::string::npos);
}

// Every character the project uses passes the check unchanged (no real asset refused).
TEST(GltfCheck, TheSharedCharactersPass) {
  for (const char* relative : {"characters/RiggedSimple.glb", "characters/CesiumMan.glb", "characters/BrainStem.glb",
                               "characters/Fox/glTF-Binary/Fox.glb", "characters/Fox/glTF/Fox.gltf"}) {
    const fs::path file = testing::SharedData(relative);
    ARVIEW_REQUIRE_DATA_PATH(file, "../shared/data");
    EXPECT_NO_THROW(CheckGltfStructure(file)) << file;
  }
}

// The reproducer itself: RiggedSimple.glb with the bytes of "inverseBindMatrices" garbled
// (fuzz_gltf's crash file, 23:26 on 2026-12-01), and with them replaced by ASCII (the key merely
// renamed, which is what makes Assimp crash: the JSON still parses).
TEST(GltfCheck, TheFuzzReproducerOnRiggedSimpleIsRefused) {
  const fs::path original = testing::SharedData("characters/RiggedSimple.glb");
  ARVIEW_REQUIRE_DATA_PATH(original, "../shared/data");
  std::ifstream in(original, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::size_t at = bytes.find("inverseBindMatrices");
  ASSERT_NE(at, std::string::npos);
  std::string garbled = bytes, renamed = bytes;
  garbled.replace(at + 8, 8, "\x92\x9b\xb2\x9e\x8b\x8d\x96\xa2");
  renamed.replace(at + 8, 8, "XXXXXXXX");
  for (const auto& [mutated, expected] : {std::pair{garbled, "the glTF JSON does not parse"},
                                          std::pair{renamed, "skins[0] has no inverseBindMatrices"}}) {
    const fs::path file = Write("asset.glb", mutated);
    try {
      (void)LoadCharacter(file);
      ADD_FAILURE() << "loaded";
    } catch (const anim::Error& e) {
      EXPECT_REFUSED(e.what(), expected);
    }
  }
}

}  // namespace
}  // namespace arview::authoring
