#include "anim_authoring/import.h"
#include "anim/pose.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;

const fs::path kBcn = "/usr/share/assimp/models/X/BCN_Epileptic.X";
const fs::path kBvh = "/usr/share/assimp/models/BVH/01_01.bvh";
fs::path Fox() { return testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"); }
fs::path CesiumMan() { return testing::SharedData("characters/CesiumMan.glb"); }

// Skins every mesh at the given pose; returns the largest distance to the rest mesh placed in
// model space, relative to the model's size.
// Vertices weighted to a joint in `skip` are left out (bones whose rest pose is not their bind
// pose in the file).
double RestSkinningError(const anim::Character& c, anim::SkinningMethod method, const std::vector<std::string>& skip = {}) {
  const anim::Skeleton& sk = c.skeleton;
  const anim::LocalPose rest = anim::LocalPose::Rest(sk);
  std::vector<Eigen::Matrix4d> model(sk.size());
  EXPECT_TRUE((anim::LocalToModelJob{&sk, &rest, model}.Run()));
  std::vector<Eigen::Matrix4f> skin(sk.size());
  std::vector<anim::DualQuatf> dq(sk.size());
  EXPECT_TRUE((anim::SkinningMatricesJob{&sk, model, skin, dq}.Run()));
  double worst = 0, extent = 0;
  for (const anim::Mesh& m : c.meshes) {
    std::vector<Eigen::Vector3f> pos(m.vertex_count()), nrm(m.vertex_count());
    EXPECT_TRUE((anim::SkinningJob{&m, method, skin, dq, pos, nrm}.Run()));
    for (int v = 0; v < m.vertex_count(); ++v) {
      bool skipped = false;
      for (int i = 0; i < 4; ++i)
        for (const auto& name : skip) skipped = skipped || (m.weights[v][i] > 0 && c.skeleton.names[m.joints[v][i]] == name);
      if (skipped) continue;
      worst = std::max(worst, double((pos[v] - m.positions[v]).norm()));
      extent = std::max(extent, double(m.positions[v].norm()));
    }
  }
  return worst / std::max(extent, 1e-9);
}

void ExpectValidSkin(const anim::Character& c) {
  for (const anim::Mesh& m : c.meshes) {
    ASSERT_EQ(m.joints.size(), m.positions.size());
    ASSERT_EQ(m.normals.size(), m.positions.size());
    ASSERT_EQ(m.indices.size() % 3, 0u);
    for (auto i : m.indices) ASSERT_LT(i, m.positions.size());
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      EXPECT_NEAR(m.weights[v].sum(), 1.0f, 1e-5f);
      EXPECT_GE(m.weights[v].minCoeff(), 0.0f);
      for (auto j : m.joints[v]) ASSERT_LT(int(j), c.skeleton.size());
    }
  }
  for (int j = 0; j < c.skeleton.size(); ++j) EXPECT_LT(c.skeleton.parents[j], j);
}

TEST(Import, Fox) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  const anim::Character c = LoadCharacter(Fox());
  EXPECT_EQ(c.skeleton.size(), 24);
  ASSERT_EQ(c.clips.size(), 3u);
  EXPECT_NE(c.FindClip("Survey"), nullptr);
  EXPECT_NE(c.FindClip("Walk"), nullptr);
  EXPECT_NE(c.FindClip("Run"), nullptr);
  EXPECT_NEAR(c.FindClip("Walk")->duration, 0.708, 0.01);
  ASSERT_EQ(c.meshes.size(), 1u);
  EXPECT_FALSE(c.meshes[0].uvs.empty());
  ASSERT_GE(c.meshes[0].material, 0);
  const anim::Material& mat = c.materials[c.meshes[0].material];
  ASSERT_GE(mat.texture, 0);
  EXPECT_EQ(c.textures[mat.texture].format_hint, "png");
  EXPECT_GT(c.textures[mat.texture].encoded.size(), 1000u);
  ExpectValidSkin(c);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kLinear), 1e-5);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kDualQuaternion), 1e-5);
}

TEST(Import, CesiumMan) {
  ARVIEW_REQUIRE_DATA_PATH(CesiumMan(), "../shared/data");
  const anim::Character c = LoadCharacter(CesiumMan());
  EXPECT_EQ(c.skeleton.size(), 19);
  EXPECT_EQ(c.clips.size(), 1u);
  ASSERT_EQ(c.meshes.size(), 1u);
  ExpectValidSkin(c);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kLinear), 1e-4);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kDualQuaternion), 1e-4);
}

TEST(Import, BcnEpilepticX) {
  ARVIEW_REQUIRE_DATA_PATH(kBcn, "Debian package assimp-testmodels");
  const anim::Character c = LoadCharacter(kBcn);
  EXPECT_EQ(c.skeleton.size(), 54);
  EXPECT_EQ(c.clips.size(), 1u);
  EXPECT_EQ(c.meshes.size(), 3u);
  EXPECT_GE(c.skeleton.Find("B_Neck"), 0);
  ExpectValidSkin(c);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kLinear), 1e-4);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kDualQuaternion), 1e-4);
}

TEST(Import, CmuBvh) {
  ARVIEW_REQUIRE_DATA_PATH(kBvh, "Debian package assimp-testmodels");
  const anim::Character c = LoadCharacter(kBvh);
  EXPECT_EQ(c.skeleton.size(), 31);
  EXPECT_TRUE(c.meshes.empty());
  ASSERT_EQ(c.clips.size(), 1u);
  const anim::Clip& clip = c.clips[0];
  EXPECT_NEAR(clip.ticks_per_second, 120.0, 1e-3);
  const int hips = c.skeleton.Find("Hips");
  ASSERT_EQ(hips, 0);
  const auto& keys = clip.tracks[hips].rotation;
  ASSERT_GT(keys.size(), 100u);
  EXPECT_NEAR(keys[1].time - keys[0].time, 1.0 / 120, 1e-6);
  EXPECT_NEAR(clip.duration, (keys.size() - 1) / 120.0, 1e-3);
}

TEST(Import, FbxSkinned) {
  const fs::path fbx = "/usr/share/assimp/models/FBX/animation_with_skeleton.fbx";
  ARVIEW_REQUIRE_DATA_PATH(fbx, "Debian package assimp-testmodels");
  const anim::Character c = LoadCharacter(fbx);
  EXPECT_EQ(c.skeleton.size(), 15);
  ASSERT_EQ(c.clips.size(), 1u);
  EXPECT_NEAR(c.clips[0].duration, 0.833, 0.01);
  ASSERT_EQ(c.meshes.size(), 1u);
  ExpectValidSkin(c);
  // In this file Bone.005 and Bone.006 rest away from their bind pose; the rest is bound as it rests.
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kLinear, {"Bone.005", "Bone.006"}), 1e-5);
  EXPECT_GT(RestSkinningError(c, anim::SkinningMethod::kLinear), 1e-2);
}

TEST(Import, ColladaSkinned) {
  const fs::path dae = "/usr/share/assimp/models/Collada/box_nested_animation.dae";
  ARVIEW_REQUIRE_DATA_PATH(dae, "Debian package assimp-testmodels");
  const anim::Character c = LoadCharacter(dae);
  EXPECT_EQ(c.skeleton.size(), 1);
  EXPECT_EQ(c.clips.size(), 1u);
  ASSERT_EQ(c.meshes.size(), 1u);
  ExpectValidSkin(c);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kLinear), 1e-5);
}

TEST(Import, ColladaRigidMeshesFollowTheirNodes) {
  // 64 animated boxes in a chain, no skin: each mesh is bound rigidly to its node.
  const fs::path dae = "/usr/share/assimp/models/Collada/anims_with_full_rotations_between_keys.DAE";
  ARVIEW_REQUIRE_DATA_PATH(dae, "Debian package assimp-testmodels");
  const anim::Character c = LoadCharacter(dae);
  EXPECT_EQ(c.skeleton.size(), 64);
  EXPECT_FALSE(c.meshes.empty());
  ExpectValidSkin(c);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kLinear), 1e-4);
  EXPECT_LT(RestSkinningError(c, anim::SkinningMethod::kDualQuaternion), 1e-4);
}

TEST(Import, SamplingInterpolatesAndLoops) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  const anim::Character c = LoadCharacter(Fox());
  const anim::Clip& walk = *c.FindClip("Walk");
  const anim::Skeleton& sk = c.skeleton;
  anim::LocalPose a(sk.size()), b(sk.size());
  ASSERT_TRUE((anim::SamplingJob{&sk, &walk, 0.1, true, &a}.Run()));
  ASSERT_TRUE((anim::SamplingJob{&sk, &walk, 0.1 + walk.duration, true, &b}.Run()));
  for (int j = 0; j < sk.size(); ++j) EXPECT_LT((a.rigid[j].ToMatrix() - b.rigid[j].ToMatrix()).norm(), 1e-9);
  // Clamp: beyond the end holds the last key.
  ASSERT_TRUE((anim::SamplingJob{&sk, &walk, 100.0, false, &a}.Run()));
  ASSERT_TRUE((anim::SamplingJob{&sk, &walk, walk.duration, false, &b}.Run()));
  for (int j = 0; j < sk.size(); ++j) EXPECT_LT((a.rigid[j].ToMatrix() - b.rigid[j].ToMatrix()).norm(), 1e-9);
  // Between two keys the rotation lies between the keys' rotations.
  const int hip = sk.Find("b_Hip_01");
  const auto& keys = walk.tracks[hip].rotation;
  ASSERT_GT(keys.size(), 2u);
  const double mid = 0.5 * (keys[0].time + keys[1].time);
  ASSERT_TRUE((anim::SamplingJob{&sk, &walk, mid, false, &a}.Run()));
  const Eigen::Quaterniond r = a.rigid[hip].Rotation();
  EXPECT_NEAR(r.angularDistance(keys[0].value), 0.5 * keys[0].value.angularDistance(keys[1].value), 1e-9);
}

// Largest rotation difference between slerp and nlerp sampling over every clip of the test
// assets, sampled at 997 times per clip.
TEST(Import, NlerpSamplingStaysCloseToSlerp) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  ARVIEW_REQUIRE_DATA_PATH(kBvh, "Debian package assimp-testmodels");
  ARVIEW_REQUIRE_DATA_PATH(kBcn, "Debian package assimp-testmodels");
  for (const fs::path& asset : {Fox(), CesiumMan(), kBcn, kBvh}) {
    const anim::Character c = LoadCharacter(asset);
    double worst = 0;
    for (const anim::Clip& clip : c.clips) {
      anim::LocalPose a(c.skeleton.size()), b(c.skeleton.size());
      for (int s = 0; s < 997; ++s) {
        const double t = clip.duration * s / 997.0;
        ASSERT_TRUE((anim::SamplingJob{&c.skeleton, &clip, t, true, &a, false}.Run()));
        ASSERT_TRUE((anim::SamplingJob{&c.skeleton, &clip, t, true, &b, true}.Run()));
        for (int j = 0; j < c.skeleton.size(); ++j)
          worst = std::max(worst, a.rigid[j].Rotation().angularDistance(b.rigid[j].Rotation()));
      }
    }
    std::printf("[nlerp] %s: largest difference from slerp %.4f deg\n", asset.filename().c_str(), worst * 180 / M_PI);
    EXPECT_LT(worst * 180 / M_PI, 1.0) << asset;
  }
}

TEST(Import, JobsRejectMismatchedSizes) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  const anim::Character c = LoadCharacter(Fox());
  anim::LocalPose wrong(3);
  EXPECT_FALSE((anim::SamplingJob{&c.skeleton, &c.clips[0], 0.0, true, &wrong}.Run()));
  std::vector<Eigen::Matrix4d> model(2);
  anim::LocalPose rest = anim::LocalPose::Rest(c.skeleton);
  EXPECT_FALSE((anim::LocalToModelJob{&c.skeleton, &rest, model}.Run()));
  anim::LocalPose out(c.skeleton.size());
  const anim::LocalPose* inputs[] = {&rest, &rest};
  const double zero[] = {0.0, 0.0}, nan[] = {NAN, 1.0}, fine[] = {0.5, 0.5};
  anim::BlendingJob blend;
  blend.inputs = inputs;
  blend.output = &out;
  blend.weights = zero;
  EXPECT_FALSE(blend.Run());
  blend.weights = nan;
  EXPECT_FALSE(blend.Run());
  blend.weights = fine;
  EXPECT_TRUE(blend.Run());
  const anim::LocalPose* mismatched[] = {&rest, &wrong};
  blend.inputs = mismatched;
  EXPECT_FALSE(blend.Run());
}

TEST(Import, AnimatedPoseLbsAndDqsAgreeRoughly) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  const anim::Character c = LoadCharacter(Fox());
  const anim::Skeleton& sk = c.skeleton;
  anim::LocalPose p(sk.size());
  ASSERT_TRUE((anim::SamplingJob{&sk, c.FindClip("Run"), 0.3, true, &p}.Run()));
  std::vector<Eigen::Matrix4d> model(sk.size());
  ASSERT_TRUE((anim::LocalToModelJob{&sk, &p, model}.Run()));
  std::vector<Eigen::Matrix4f> skin(sk.size());
  std::vector<anim::DualQuatf> dq(sk.size());
  ASSERT_TRUE((anim::SkinningMatricesJob{&sk, model, skin, dq}.Run()));
  EXPECT_TRUE(anim::RigidSkinning(skin));
  const anim::Mesh& m = c.meshes[0];
  std::vector<Eigen::Vector3f> lbs(m.vertex_count()), dqs(m.vertex_count());
  ASSERT_TRUE((anim::SkinningJob{&m, anim::SkinningMethod::kLinear, skin, dq, lbs, {}}.Run()));
  ASSERT_TRUE((anim::SkinningJob{&m, anim::SkinningMethod::kDualQuaternion, skin, dq, dqs, {}}.Run()));
  double worst = 0, moved = 0;
  for (int v = 0; v < m.vertex_count(); ++v) {
    worst = std::max(worst, double((lbs[v] - dqs[v]).norm()));
    moved = std::max(moved, double((lbs[v] - m.positions[v]).norm()));
  }
  EXPECT_GT(moved, 1.0);       // the run pose really moves the mesh (model units: cm)
  EXPECT_LT(worst, 0.2 * moved);  // the two skinning methods differ only near blended joints
  // Rigidly bound vertices (one influence) agree exactly.
  for (int v = 0; v < m.vertex_count(); ++v) {
    if (m.weights[v][0] == 1.0f) {
      EXPECT_LT((lbs[v] - dqs[v]).norm(), 1e-3f);
    }
  }
}

fs::path TempFile(const std::string& name) { return fs::temp_directory_path() / ("arview_anim_" + name); }

TEST(ImportErrors, MissingFile) {
  try {
    LoadCharacter("/nonexistent/dir/fox.glb");
    FAIL();
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/fox.glb: no such file"), std::string::npos) << e.what();
  }
}

TEST(ImportErrors, TruncatedGltf) {
  ARVIEW_REQUIRE_DATA_PATH(Fox(), "../shared/data");
  std::ifstream in(Fox(), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const fs::path cut = TempFile("truncated.glb");
  std::ofstream(cut, std::ios::binary).write(bytes.data(), bytes.size() / 3);
  try {
    LoadCharacter(cut);
    FAIL();
  } catch (const anim::Error& e) {
    // Refused by the structure check before Assimp (anim_authoring/gltf_check.h).
    EXPECT_NE(std::string(e.what()).find(cut.string() + ": the GLB header gives a length of"), std::string::npos)
        << e.what();
  }
  fs::remove(cut);
}

TEST(ImportErrors, NoSkeleton) {
  const fs::path obj = TempFile("cube.obj");
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  try {
    LoadCharacter(obj);
    FAIL();
  } catch (const anim::Error& e) {
    EXPECT_NE(std::string(e.what()).find(obj.string() + ": no skeleton"), std::string::npos) << e.what();
  }
  fs::remove(obj);
}

}  // namespace
}  // namespace arview::authoring
