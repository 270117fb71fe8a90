// Morph targets, in the vertex shader and on the renderer's CPU path (render/cpu_morphs.h):
// AnimatedMorphCube (Debian's assimp-testmodels) drawn with its targets weighted against the same
// cube with the deltas added by anim/morph.h, drawn through the same renderer, camera and
// placement without targets.

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdlib>

#include "anim/animator.h"
#include "anim/morph.h"
#include "anim_authoring/import.h"
#include "render/ar_renderer.h"
#include "render/test_scene.h"
#include "tests/support/fox_view.h"
#include "tests/support/test_data.h"

namespace arview::render {
namespace {

namespace fs = std::filesystem;

const fs::path kCube = "/usr/share/assimp/models/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf";

calib::Camera TestCamera() { return calib::Camera::Pinhole(640, 480, 600, 590, 322.5, 236.0); }

// From 1.6 m in front and above, at the cube (0.5 m across after the placement's scale), z up.
calib::Pose LookingAtCube() { return arview::testing::LookingAt({0.7, -1.3, 0.9}, {0, 0, 0.2}); }

anim::Placement CubePlacement() {
  anim::Placement p;
  p.scale = 0.25;
  p.anchor.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
  return p;
}

// The cube with the weighted deltas added to its vertices and no targets left.
anim::Character MorphedOnCpu(const anim::Character& cube, std::span<const float> weights) {
  anim::Character c = cube;
  for (anim::Mesh& m : c.meshes) {
    std::vector<Eigen::Vector3f> positions, normals;
    anim::ApplyMorphTargets(m, weights, positions, normals);
    m.positions = positions;
    m.normals = normals;
    m.morphs.clear();
  }
  c.skeleton.morph_targets.clear();
  for (anim::Clip& clip : c.clips) clip.weight_tracks.clear();
  return c;
}

struct Comparison {
  cv::Mat gpu, cpu;
  int pixels = 0;      // of the cube, in either picture
  int over_one = 0;    // differing by more than one grey level in some channel
  int max_difference = 0;
};

class MorphCube : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(kCube, "Debian package assimp-testmodels");
    cube_ = authoring::LoadCharacter(kCube);
    frame_buffers_ = anim::FrameBuffers(cube_.skeleton);
    frame_buffers_.Finish(cube_.skeleton, frame_, "rest", "skin");
  }

  // `cpu_morph_max_deltas`: ArOptions' (0: the vertex shader; the cube's 24 vertices go through
  // the CPU at the default).
  Comparison Compare(std::span<const float> weights, anim::SkinningMethod method, const std::string& label,
                     int cpu_morph_max_deltas = 0) {
    ArOptions options;
    options.cpu_morph_max_deltas = cpu_morph_max_deltas;
    options.shadow = false;
    options.skinning = method;
    options.empty_background = cv::Scalar(255, 0, 255);
    const calib::Camera camera = TestCamera();
    const calib::Pose pose = LookingAtCube();
    Comparison c;
    {
      ArRenderer renderer(testing::SharedContext(), camera, options);
      renderer.AddCharacter(cube_, CubePlacement());
      anim::AnimatorFrame frame = frame_;
      frame.morph_weights = weights;
      const anim::AnimatorFrame* frames[] = {&frame};
      c.gpu = renderer.Render({}, pose, frames);
    }
    {
      const anim::Character reference = MorphedOnCpu(cube_, weights);
      ArRenderer renderer(testing::SharedContext(), camera, options);
      renderer.AddCharacter(reference, CubePlacement());
      anim::AnimatorFrame frame = frame_;
      frame.morph_weights = {};
      const anim::AnimatorFrame* frames[] = {&frame};
      c.cpu = renderer.Render({}, pose, frames);
    }
    cv::Mat diff, channel_max, background_gpu, background_cpu;
    cv::absdiff(c.gpu, c.cpu, diff);
    cv::Mat planes[3];
    cv::split(diff, planes);
    channel_max = cv::max(cv::max(planes[0], planes[1]), planes[2]);
    double max_value = 0;
    cv::minMaxLoc(channel_max, nullptr, &max_value);
    c.max_difference = static_cast<int>(max_value);
    c.over_one = cv::countNonZero(channel_max > 1);
    cv::inRange(c.gpu, cv::Scalar(255, 0, 255), cv::Scalar(255, 0, 255), background_gpu);
    cv::inRange(c.cpu, cv::Scalar(255, 0, 255), cv::Scalar(255, 0, 255), background_cpu);
    c.pixels = cv::countNonZero(~(background_gpu & background_cpu));
    if (const char* dir = std::getenv("ARVIEW_MORPH_PICTURES"); dir && *dir) {
      cv::Mat side;
      cv::hconcat(c.gpu, c.cpu, side);
      cv::imwrite((fs::path(dir) / ("morph_cube_" + label + ".png")).string(), side);
    }
    std::printf("%s: %d cube pixels, max difference %d, %d pixels over 1 level\n", label.c_str(), c.pixels,
                c.max_difference, c.over_one);
    return c;
  }

  anim::Character cube_;
  anim::FrameBuffers frame_buffers_;
  anim::AnimatorFrame frame_;
};

TEST_F(MorphCube, WeightedTargetsMatchTheDeltasAddedOnTheCpuWithinOneLevel) {
  const std::vector<std::vector<float>> weights = {{0, 0}, {1, 0}, {0, 1}, {0.5f, 0.5f}, {0.8f, -0.3f}};
  for (auto method : {anim::SkinningMethod::kDualQuaternion, anim::SkinningMethod::kLinear}) {
    for (const auto& w : weights) {
      const std::string label = std::string(method == anim::SkinningMethod::kLinear ? "lbs" : "dqs") + "_" +
                                std::to_string(w[0]).substr(0, 4) + "_" + std::to_string(w[1]).substr(0, 4);
      const Comparison c = Compare(w, method, label);
      EXPECT_GT(c.pixels, 5000) << label << ": the cube fills part of the view";
      EXPECT_LE(c.max_difference, 1) << label;
    }
  }
}

// The renderer's CPU path (the default for few deltas) gives the same picture as the shader.
TEST_F(MorphCube, TheCpuPathDrawsWhatTheShaderDraws) {
  for (const std::vector<float>& w : {std::vector<float>{1, 0}, std::vector<float>{0.8f, -0.3f}}) {
    const Comparison shader = Compare(w, anim::SkinningMethod::kDualQuaternion, "shader");
    const Comparison cpu = Compare(w, anim::SkinningMethod::kDualQuaternion, "cpu_path",
                                   CharacterRenderer::kDefaultCpuMorphMaxDeltas);
    cv::Mat diff;
    cv::absdiff(shader.gpu, cpu.gpu, diff);
    double most = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &most);
    EXPECT_LE(most, 1) << w[0] << ", " << w[1];
    EXPECT_LE(cpu.max_difference, 1) << "against anim/morph.h's deltas";
  }
}

TEST_F(MorphCube, TheClipsWeightsAtSeveralTimesMatchTheCpu) {
  ASSERT_EQ(cube_.clips.size(), 1u);
  anim::LocalPose pose = anim::LocalPose::Rest(cube_.skeleton);
  for (double t : {0.6, 1.5, 2.4, 3.3}) {
    ASSERT_TRUE((anim::SamplingJob{&cube_.skeleton, &cube_.clips[0], t, false, &pose}.Run()));
    const Comparison c = Compare(pose.morph, anim::SkinningMethod::kDualQuaternion, "t" + std::to_string(t).substr(0, 3));
    EXPECT_LE(c.max_difference, 1) << "t = " << t;
  }
}

TEST_F(MorphCube, WeightedTargetsChangeThePicture) {
  const std::vector<float> none{0, 0}, thin{1, 0};
  const Comparison rest = Compare(none, anim::SkinningMethod::kDualQuaternion, "rest");
  const Comparison morphed = Compare(thin, anim::SkinningMethod::kDualQuaternion, "thin");
  cv::Mat diff;
  cv::absdiff(rest.gpu, morphed.gpu, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(diff > 10), 1000) << "the first target moves the cube's top";
}

// The drawn rectangle grows with the weighted targets: weights that push the cube beyond its rest
// size (negative, and over 1) give the full-frame picture.
TEST_F(MorphCube, TheBoundedRenderHoldsTheMorphedCube) {
  for (const std::vector<float>& w : {std::vector<float>{-1.5f, 0}, std::vector<float>{0, 2.5f}, std::vector<float>{-1, -1}}) {
    cv::Mat pictures[2];
    for (const bool full : {false, true}) {
      ArOptions options;
      options.shadow = false;
      options.full_frame = full;
      ArRenderer renderer(testing::SharedContext(), TestCamera(), options);
      renderer.AddCharacter(cube_, CubePlacement());
      anim::AnimatorFrame frame = frame_;
      frame.morph_weights = w;
      const anim::AnimatorFrame* frames[] = {&frame};
      pictures[full] = renderer.Render({}, LookingAtCube(), frames);
    }
    cv::Mat diff;
    cv::absdiff(pictures[0], pictures[1], diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(diff > 1), 0) << w[0] << ", " << w[1];
  }
}

// The warm-up also draws the morphing programs (every target barely weighted) and leaves no trace.
TEST_F(MorphCube, TheWarmUpDrawsTheMorphingProgramAndLeavesNoTrace) {
  const std::vector<float> w{0.4f, 0.6f};
  anim::AnimatorFrame frame = frame_;
  frame.morph_weights = w;
  const anim::AnimatorFrame* frames[] = {&frame};
  cv::Mat pictures[2];
  for (const bool warm : {false, true}) {
    ArRenderer renderer(testing::SharedContext(), TestCamera(), {});
    renderer.AddCharacter(cube_, CubePlacement());
    const anim::AnimatorFrame* rest[] = {&frame_};
    if (warm) renderer.WarmUp(LookingAtCube(), rest);
    pictures[warm] = renderer.Render({}, LookingAtCube(), frames);
  }
  cv::Mat diff;
  cv::absdiff(pictures[0], pictures[1], diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
}

TEST_F(MorphCube, AWrongNumberOfWeightsIsRefused) {
  ArRenderer renderer(testing::SharedContext(), TestCamera(), {});
  renderer.AddCharacter(cube_, CubePlacement());
  const std::vector<float> three{0, 0, 1};
  anim::AnimatorFrame frame = frame_;
  frame.morph_weights = three;
  const anim::AnimatorFrame* frames[] = {&frame};
  EXPECT_THROW(renderer.Render({}, LookingAtCube(), frames), RenderError);
}

}  // namespace
}  // namespace arview::render
