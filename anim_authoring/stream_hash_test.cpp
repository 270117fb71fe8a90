// Fingerprints of the idle synthesizer's streams, to compare two builds bit for bit: a change
// meant only to make the synthesizer cheaper (docs/anim.md, "What the check costs") must leave
// every hash as it was. FNV-1a over the clamped postures of 10-minute streams at 30 Hz (the
// Fox's Survey model and BCN_Epileptic's, seeds 1–12 each) and over the four-action schedule's
// skinning matrices for 10 minutes at 60 Hz (tests/support/four_action_schedule.h, point
// gesture, DLB). The values depend on the platform's libm, so the test prints them and asserts
// only that they repeat within a build:
//   anim_authoring_tests --gtest_filter='StreamHash.*' | grep '\[hash\]'   (before and after)

#include "anim_authoring/animator_builder.h"
#include "anim_authoring/idle_learning.h"
#include "base/hash.h"
#include "anim_authoring/import.h"
#include "tests/support/four_action_schedule.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>

namespace arview::authoring {
namespace {

std::uint64_t PostureHash(const std::shared_ptr<const anim::Skeleton>& skeleton, const std::shared_ptr<const anim::IdleModel>& model,
                          std::uint64_t seed) {
  anim::IdleSynthesizer idle(skeleton, model, seed);
  Fnv1a h;
  for (int f = 0; f < 600 * 30; ++f) {
    const Eigen::VectorXd& p = idle.Posture(f / 30.0);
    h.Add(p.data(), sizeof(double) * p.size());
  }
  return h.hash;
}

TEST(StreamHash, IdleStreamsAndFourActionSchedule) {
  ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("characters/Fox"), "../shared/data");
  ARVIEW_REQUIRE_DATA_PATH(testing::kBcnEpileptic, "Debian package assimp-testmodels");
  const anim::Character fox = LoadCharacter(testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"));
  const std::vector<IdleSource> sources{{&fox, {fox.FindClip("Survey")}, true}};
  const auto fox_skeleton = std::make_shared<const anim::Skeleton>(fox.skeleton);
  const auto fox_model = std::make_shared<const anim::IdleModel>(LearnIdleModel(fox.skeleton, sources, IdleLearningOptions{}));
  testing::FourActionSchedule schedule(testing::FourActionSchedule::Gesture::kPoint, /*dib=*/false);
  const auto bcn_skeleton = schedule.character().shared_skeleton();
  const auto bcn_model = std::make_shared<const anim::IdleModel>(BuildIdle(schedule.character())->model());

  Fnv1a all;
  for (int seed = 1; seed <= 12; ++seed) {
    const std::uint64_t fox_hash = PostureHash(fox_skeleton, fox_model, seed);
    const std::uint64_t bcn_hash = PostureHash(bcn_skeleton, bcn_model, seed);
    std::printf("[hash] seed %2d: Fox Survey %016llx, BCN_Epileptic %016llx\n", seed, static_cast<unsigned long long>(fox_hash),
                static_cast<unsigned long long>(bcn_hash));
    all.Add(&fox_hash, sizeof fox_hash);
    all.Add(&bcn_hash, sizeof bcn_hash);
  }
  Fnv1a matrices;
  for (int f = 0; f < 600 * 60; ++f)
    for (const Eigen::Matrix4f& m : schedule.Step(1.0 / 60).skinning_matrices) matrices.Add(m.data(), sizeof(float) * 16);
  std::printf("[hash] four-action schedule (point gesture, DLB), 10 min of skinning matrices: %016llx\n",
              static_cast<unsigned long long>(matrices.hash));
  all.Add(&matrices.hash, sizeof matrices.hash);
  std::printf("[hash] all: %016llx\n", static_cast<unsigned long long>(all.hash));

  // They repeat: a new synthesizer with the same seed gives the same stream.
  EXPECT_EQ(PostureHash(fox_skeleton, fox_model, 7), PostureHash(fox_skeleton, fox_model, 7));
  EXPECT_EQ(PostureHash(bcn_skeleton, bcn_model, 7), PostureHash(bcn_skeleton, bcn_model, 7));
}

}  // namespace
}  // namespace arview::authoring
