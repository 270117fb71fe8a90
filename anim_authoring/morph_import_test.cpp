// glTF morph targets through Assimp: AnimatedMorphCube (Debian's assimp-testmodels) and copies
// of it edited to carry target names, a non-finite delta, or weights that do not fit.

#include "anim/morph.h"
#include "anim_authoring/import.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;

const fs::path kCubeDir = "/usr/share/assimp/models/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF";
const fs::path kCube = kCubeDir / "AnimatedMorphCube.gltf";

#define REQUIRE_CUBE() ARVIEW_REQUIRE_DATA_PATH(kCube, "Debian package assimp-testmodels")

nlohmann::json CubeJson() {
  std::ifstream in(kCube);
  return nlohmann::json::parse(in);
}

// The cube's glTF, edited, beside a copy of its buffer (which `edit_bin` may change) in a fresh
// folder; returns the .gltf's path.
fs::path EditedCube(const std::string& name, const std::function<void(nlohmann::json&)>& edit,
                    const std::function<void(std::string&)>& edit_bin = {}) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("morph_cube_" + name);
  fs::create_directories(dir);
  std::ifstream bin_in(kCubeDir / "AnimatedMorphCube.bin", std::ios::binary);
  std::string bin((std::istreambuf_iterator<char>(bin_in)), std::istreambuf_iterator<char>());
  if (edit_bin) edit_bin(bin);
  std::ofstream(dir / "AnimatedMorphCube.bin", std::ios::binary) << bin;
  nlohmann::json doc = CubeJson();
  edit(doc);
  const fs::path out = dir / (name + ".gltf");
  std::ofstream(out) << doc.dump();
  return out;
}

std::string ErrorOf(const fs::path& asset) {
  try {
    LoadCharacter(asset);
  } catch (const anim::Error& e) {
    return e.what();
  }
  return "";
}

float LargestDelta(const anim::Mesh& mesh, int target) {
  float largest = 0;
  for (const anim::MeshMorph& m : mesh.morphs)
    if (m.target == target)
      for (const Eigen::Vector3f& d : m.position_deltas) largest = std::max(largest, d.norm());
  return largest;
}

TEST(MorphImport, AnimatedMorphCubeHasTwoTargetsAndAWeightClip) {
  REQUIRE_CUBE();
  const anim::Character c = LoadCharacter(kCube);
  ASSERT_EQ(c.skeleton.size(), 1) << "the mesh's node is the skeleton";
  ASSERT_EQ(c.skeleton.morph_target_count(), 2);
  // No extras.targetNames in this file: the mesh's name and the target's index.
  EXPECT_EQ(c.skeleton.morph_targets[0], "Cube#0");
  EXPECT_EQ(c.skeleton.morph_targets[1], "Cube#1");
  ASSERT_EQ(c.meshes.size(), 1u);
  ASSERT_EQ(c.meshes[0].morphs.size(), 2u);
  // The file's largest deltas (accessors 4 and 7: y up to 0.01893 and 0.01989), in model space
  // through the node's scale of 100, as the base mesh is.
  EXPECT_NEAR(LargestDelta(c.meshes[0], 0), 1.893253, 1e-4);
  EXPECT_NEAR(LargestDelta(c.meshes[0], 1), 1.989084, 1e-4);
  ASSERT_EQ(c.clips.size(), 1u);
  const anim::Clip& clip = c.clips[0];
  EXPECT_EQ(clip.name, "Square");
  EXPECT_NEAR(clip.duration, 4.2, 1e-3);
  ASSERT_EQ(clip.weight_tracks.size(), 2u);
  for (const anim::WeightTrack& t : clip.weight_tracks) EXPECT_EQ(t.weights.size(), 127u);
  // Sampled: both weights within [0, 1], each reaching 1 at some time.
  anim::LocalPose pose = anim::LocalPose::Rest(c.skeleton);
  float peak[2] = {0, 0};
  for (double t = 0; t <= clip.duration; t += 0.05) {
    ASSERT_TRUE((anim::SamplingJob{&c.skeleton, &clip, t, false, &pose}.Run()));
    for (int k = 0; k < 2; ++k) {
      EXPECT_GE(pose.morph[k], -1e-6f);
      EXPECT_LE(pose.morph[k], 1 + 1e-6f);
      peak[k] = std::max(peak[k], pose.morph[k]);
    }
  }
  EXPECT_GT(peak[0], 0.99f);
  EXPECT_GT(peak[1], 0.99f);
}

TEST(MorphImport, TargetNamesComeFromExtrasTargetNames) {
  REQUIRE_CUBE();
  const fs::path named = EditedCube("named", [](nlohmann::json& d) { d["meshes"][0]["extras"]["targetNames"] = {"thin", "angle"}; });
  const anim::Character c = LoadCharacter(named);
  EXPECT_EQ(c.skeleton.morph_targets, (std::vector<std::string>{"thin", "angle"}));
}

TEST(MorphImport, ANonFiniteDeltaIsOneErrorNamingTheAssetAndTheTarget) {
  REQUIRE_CUBE();
  const fs::path bad = EditedCube(
      "nan", [](nlohmann::json& d) { d["meshes"][0]["extras"]["targetNames"] = {"thin", "angle"}; },
      [](std::string& bin) {
        const float nan = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(bin.data() + 2112 + 12 * 5 + 4, &nan, 4);  // accessor 7 ("angle" POSITION), vertex 5, y
      });
  const std::string e = ErrorOf(bad);
  EXPECT_NE(e.find(bad.string()), std::string::npos) << e;
  EXPECT_NE(e.find("morph target 'angle'"), std::string::npos) << e;
  EXPECT_NE(e.find("non-finite"), std::string::npos) << e;
}

TEST(MorphImport, ATargetWithAnotherVertexCountIsOneErrorNamingTheAssetAndTheTarget) {
  REQUIRE_CUBE();
  const fs::path bad = EditedCube("count", [](nlohmann::json& d) {
    d["accessors"][7]["count"] = 12;
    d["accessors"][7].erase("max");
    d["accessors"][7].erase("min");
  });
  const std::string e = ErrorOf(bad);
  EXPECT_NE(e.find(bad.string()), std::string::npos) << e;
  EXPECT_NE(e.find("targets[1].POSITION has 12 elements, POSITION has 24"), std::string::npos) << e;
}

TEST(MorphImport, WeightsForAMissingTargetAreOneErrorNamingTheAssetAndTheMesh) {
  REQUIRE_CUBE();
  // One target left, the animation still keys two per time.
  const fs::path bad = EditedCube("missing", [](nlohmann::json& d) {
    auto& targets = d["meshes"][0]["primitives"][0]["targets"];
    targets.erase(1);
    d["meshes"][0]["weights"] = {0.0};
  });
  const std::string e = ErrorOf(bad);
  EXPECT_NE(e.find(bad.string()), std::string::npos) << e;
  EXPECT_NE(e.find("254 weights for 127 key times and the 1 morph targets of mesh 'Cube'"), std::string::npos) << e;
}

TEST(MorphImport, CharactersWithoutTargetsHaveNone) {
  for (const fs::path& asset : {testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"),
                                fs::path("/usr/share/assimp/models/X/BCN_Epileptic.X")}) {
    if (!fs::exists(asset)) continue;
    const anim::Character c = LoadCharacter(asset);
    EXPECT_EQ(c.skeleton.morph_target_count(), 0) << asset;
    for (const anim::Mesh& m : c.meshes) EXPECT_TRUE(m.morphs.empty()) << asset;
    for (const anim::Clip& clip : c.clips) EXPECT_TRUE(clip.weight_tracks.empty()) << asset;
  }
}

}  // namespace
}  // namespace arview::authoring
