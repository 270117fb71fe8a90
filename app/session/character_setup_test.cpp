#include "app/session/character_setup.h"

#include <gtest/gtest.h>

#include "tests/support/test_data.h"

namespace arview::app {
namespace {

// The Fox with 8 generated look-at keys on the horizon, standing at the map origin.
authoring::CharacterSpec FoxSpec() {
  const auto fox = arview::testing::SharedData("characters/Fox/glTF-Binary/Fox.glb");
  std::string yaml = "characters:\n  - name: fox\n    asset: " + fox.string() +
                     "\n    lookat:\n      base_clip: Survey\n    keys:\n";
  for (int k = 0; k < 8; ++k) yaml += "      - azimuth: " + std::to_string(45 * k) + "\n        generate: lookat\n";
  return authoring::ParseScene(yaml, "fox-test.yaml").characters.at(0);
}

double MaxJump(std::span<const Eigen::Matrix4f> a, const std::vector<Eigen::Matrix4f>& b) {
  double m = 0;
  for (size_t j = 0; j < a.size(); ++j) m = std::max(m, static_cast<double>((a[j] - b[j]).cwiseAbs().maxCoeff()));
  return m;
}

TEST(LayeredAnimator, HoldsThenFadesToIdleAndBackWithoutJumps) {
  ARVIEW_REQUIRE_DATA_PATH(arview::testing::SharedData("characters/Fox"), "../shared/data");
  authoring::AnimatedCharacter fox(FoxSpec());
  std::unique_ptr<LayeredAnimator> animator = MakeLayeredAnimator(fox, "", {0.5, 1.0});
  ASSERT_NE(animator->idle_clip(), nullptr);
  EXPECT_EQ(animator->idle_clip()->name, "Survey");

  const double dt = 1.0 / 30;
  const Eigen::Vector3d camera(2, 0.5, 1);  // to the fox's front-left
  std::vector<Eigen::Matrix4f> previous;
  double worst_jump_tracked = 0, worst_jump_fading = 0;
  for (int i = 0; i < 150; ++i) {
    const double t = i * dt;
    // Tracked for 1 s, lost for 2 s, tracked again for 2 s.
    const bool lost = i >= 30 && i < 90;
    const anim::AnimatorFrame& f = animator->Update(lost ? std::nullopt : std::optional(camera), t);
    if (i < 30) {
      EXPECT_EQ(f.idle_weight(), 0);
    } else if (i < 30 + 14) {
      EXPECT_EQ(f.idle_weight(), 0) << "holds for 0.5 s";
    } else if (i >= 30 + 15 + 31 && i < 90) {
      EXPECT_EQ(f.idle_weight(), 1) << "faded fully after 1 s";
    } else if (i >= 90 + 31) {
      EXPECT_EQ(f.idle_weight(), 0) << "faded back after relocalization";
    }
    std::vector<Eigen::Matrix4f> current(f.skinning_matrices.begin(), f.skinning_matrices.end());
    if (!previous.empty()) {
      const double jump = MaxJump(f.skinning_matrices, previous);
      const bool fading = f.idle_weight() > 0 && f.idle_weight() < 1;
      double& worst = fading ? worst_jump_fading : worst_jump_tracked;
      worst = std::max(worst, jump);
    }
    previous = current;
  }
  // The fade changes the pose no faster than the animation itself does.
  EXPECT_LT(worst_jump_fading, 2.0 * worst_jump_tracked + 1e-3);
}

TEST(LayeredAnimator, UnknownIdleClipIsAnError) {
  ARVIEW_REQUIRE_DATA_PATH(arview::testing::SharedData("characters/Fox"), "../shared/data");
  authoring::AnimatedCharacter fox(FoxSpec());
  EXPECT_THROW(MakeLayeredAnimator(fox, "Dance"), anim::Error);
}

// The scene asks for balance shifts from a recording that holds none (CMU 01_01): the animator
// runs on the idle synthesizer alone and says why in one note, which replay, run and view print.
TEST(LayeredAnimator, NotesABalanceLayerItsDataCannotSupport) {
  const std::string bcn = "/usr/share/assimp/models/X/BCN_Epileptic.X", cmu = "/usr/share/assimp/models/BVH/01_01.bvh";
  ARVIEW_REQUIRE_DATA_PATH(std::filesystem::path(cmu), "Debian package assimp-testmodels");
  const authoring::Scene scene = authoring::ParseScene("characters:\n  - asset: " + bcn +
                                                 "\n    keys: [{azimuth: 0, generate: lookat}]\n    idle:\n      clips: "
                                                 "[Epileptisch]\n      balance: {motion: " + cmu + "}\n",
                                             "bcn-test.yaml");
  authoring::AnimatedCharacter bcn_character(scene.characters.at(0));
  std::unique_ptr<LayeredAnimator> animator = MakeLayeredAnimator(bcn_character);
  ASSERT_EQ(animator->notes().size(), 1u);
  EXPECT_EQ(animator->notes()[0].rfind("bcn-test.yaml:6: idle.balance: " + cmu + ": ", 0), 0u) << animator->notes()[0];
  EXPECT_NE(animator->notes()[0].find("0 transitions"), std::string::npos) << animator->notes()[0];
  EXPECT_TRUE(animator->Update(Eigen::Vector3d(0, 1, 3), 0.5).skinning_matrices[0].allFinite());
}

}  // namespace
}  // namespace arview::app
