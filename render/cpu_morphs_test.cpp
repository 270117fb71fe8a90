// The renderer's CPU morph path (render/cpu_morphs.h): the same sums as anim/morph.h on
// AnimatedMorphCube (Debian's assimp-testmodels), and which meshes CharacterRenderer sends
// through it. The pictures of both paths are compared in morph_test.cpp.

#include "render/cpu_morphs.h"

#include <gtest/gtest.h>

#include "anim/animator.h"
#include "anim/morph.h"
#include "anim_authoring/import.h"
#include "render/character_renderer.h"
#include "render/gl_objects.h"
#include "render/test_scene.h"
#include "tests/support/test_data.h"

namespace arview::render {
namespace {

const std::filesystem::path kCube =
    "/usr/share/assimp/models/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf";

TEST(CpuMorphs, AddsTheWeightedDeltasAsAnimDoes) {
  ARVIEW_REQUIRE_DATA_PATH(kCube, "Debian package assimp-testmodels");
  const anim::Character cube = authoring::LoadCharacter(kCube);
  const int targets = cube.skeleton.morph_target_count();
  ASSERT_EQ(targets, 2);
  for (const anim::Mesh& mesh : cube.meshes) {
    CpuMorphs morphs(mesh, targets);
    const std::vector<int> both{0, 1};
    EXPECT_EQ(morphs.DeltaCount(both), mesh.morphs[0].vertices.size() + mesh.morphs[1].vertices.size());
    EXPECT_EQ(morphs.DeltaCount(std::vector<int>{1}), mesh.morphs[1].vertices.size());
    for (const std::vector<float>& w : {std::vector<float>{0, 0}, std::vector<float>{1, 0}, std::vector<float>{0.8f, -0.3f}}) {
      std::vector<Eigen::Vector3f> positions, normals;
      anim::ApplyMorphTargets(mesh, w, positions, normals);
      const std::span<const float> got = morphs.Apply(both, w);
      ASSERT_EQ(got.size(), mesh.positions.size() * CpuMorphs::kFloatsPerVertex);
      for (size_t v = 0; v < mesh.positions.size(); ++v) {
        for (int c = 0; c < 3; ++c) {
          EXPECT_FLOAT_EQ(got[v * 6 + c], positions[v][c]) << "vertex " << v;
          EXPECT_FLOAT_EQ(got[v * 6 + 3 + c], normals[v][c]) << "vertex " << v;
        }
      }
    }
    // Only the listed targets count: target 1 alone, whatever target 0's weight would be.
    std::vector<Eigen::Vector3f> positions, normals;
    anim::ApplyMorphTargets(mesh, std::vector<float>{0, 0.5f}, positions, normals);
    const std::span<const float> second = morphs.Apply(std::vector<int>{1}, std::vector<float>{0.5f});
    for (size_t v = 0; v < mesh.positions.size(); ++v) EXPECT_FLOAT_EQ(second[v * 6 + 1], positions[v].y());
  }
}

// The cube's few deltas go through the CPU at the default limit, through the shader under it.
TEST(CpuMorphs, TheRendererChoosesThePathByTheWeightedDeltas) {
  ARVIEW_REQUIRE_DATA_PATH(kCube, "Debian package assimp-testmodels");
  const anim::Character cube = authoring::LoadCharacter(kCube);
  anim::FrameBuffers buffers(cube.skeleton);
  anim::AnimatorFrame frame;
  buffers.Finish(cube.skeleton, frame, "rest", "skin");
  const std::vector<float> weights{0.7f, 0.2f};
  CharacterDraw draw;
  draw.skinning_matrices = frame.skinning_matrices;
  draw.skinning_dual_quats = frame.skinning_dual_quats;
  draw.morph_weights = weights;
  const Eigen::Matrix4d identity = Eigen::Matrix4d::Identity();

  const GlApi& gl = testing::SharedContext().gl();
  RenderTarget target(gl, 64, 64, 1);
  target.Bind();
  CharacterRenderer renderer(gl, cube);
  EXPECT_EQ(renderer.cpu_morph_max_deltas(), CharacterRenderer::kDefaultCpuMorphMaxDeltas);
  renderer.Draw(identity, identity, draw);
  EXPECT_EQ(renderer.morphed_meshes_on_cpu(), static_cast<int>(cube.meshes.size()));
  EXPECT_EQ(renderer.morph_targets_applied(), 2 * static_cast<int>(cube.meshes.size()));

  renderer.set_cpu_morph_max_deltas(0);
  renderer.Draw(identity, identity, draw);
  EXPECT_EQ(renderer.morphed_meshes_on_cpu(), 0);
  EXPECT_EQ(renderer.morph_targets_applied(), 2 * static_cast<int>(cube.meshes.size()));

  draw.morph_weights = {};
  renderer.set_cpu_morph_max_deltas(CharacterRenderer::kDefaultCpuMorphMaxDeltas);
  renderer.Draw(identity, identity, draw);
  EXPECT_EQ(renderer.morphed_meshes_on_cpu(), 0) << "nothing weighted: the rest pose as uploaded";
  CheckGl(gl, "the three draws");
}

}  // namespace
}  // namespace arview::render
