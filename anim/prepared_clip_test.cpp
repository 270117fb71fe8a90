// PreparedClip + PreparedSamplingJob give SamplingJob's poses (to rounding) on clips built to
// exercise every case: shared and separate timelines, uneven key spacing, one key, no key (the
// rest), rotation keys up to π apart, on opposite sides of the double cover, nearly equal; and
// on every clip of the test assets.

#include "anim/prepared_clip.h"

#include "anim_authoring/import.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace arview::anim {
namespace {

constexpr int kJoints = 12;

Skeleton MakeSkeleton(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Skeleton sk;
  for (int j = 0; j < kJoints; ++j) {
    sk.names.push_back("j" + std::to_string(j));
    sk.parents.push_back(j - 1);
    sk.rest.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)),
                       Eigen::Quaterniond(Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())),
                       Eigen::Vector3d(1 + 0.1 * u(rng), 1, 1)});
    sk.inverse_bind.push_back(Eigen::Matrix4d::Identity());
  }
  return sk;
}

Eigen::Quaterniond RandomRotation(std::mt19937& rng, double max_angle) {
  std::uniform_real_distribution<double> u(-1, 1);
  return Eigen::Quaterniond(Eigen::AngleAxisd(max_angle * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
}

Clip MakeClip(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Clip clip;
  clip.name = "synthetic";
  clip.duration = 2.0;
  const std::vector<double> even = {0.0, 0.5, 1.0, 1.5, 2.0};
  const std::vector<double> uneven = {0.1, 0.2, 0.25, 0.9, 1.0, 1.95};
  const std::vector<double> other = {0.0, 0.3, 0.6, 0.9, 1.2, 1.5, 1.8};
  clip.tracks.resize(kJoints);
  for (int j = 0; j < kJoints; ++j) {
    JointTrack& tr = clip.tracks[j];
    const std::vector<double>& times = j % 3 == 0 ? even : j % 3 == 1 ? uneven : other;
    const int kind = j % 4;  // 0: keyed, 1: one key, 2: no key, 3: keyed on another timeline
    if (kind == 0 || kind == 3) {
      Eigen::Quaterniond q = RandomRotation(rng, M_PI);
      for (std::size_t i = 0; i < times.size(); ++i) {
        // Steps of every size up to π, a sign flip now and then, and a pair of equal keys.
        if (i == 2) {
          tr.rotation.push_back({times[i], q});
          continue;
        }
        q = (RandomRotation(rng, (i + 1) * M_PI / times.size()) * q).normalized();
        if (i % 2 == 1) q.coeffs() = -q.coeffs();
        tr.rotation.push_back({times[i], q});
      }
    } else if (kind == 1) {
      tr.rotation.push_back({0.3, RandomRotation(rng, 1.0)});
    }
    const std::vector<double>& vtimes = kind == 3 ? other : times;
    if (kind != 2)
      for (double t : vtimes) tr.translation.push_back({t, Eigen::Vector3d(u(rng), u(rng), u(rng))});
    if (kind == 0)
      for (double t : times) tr.scale.push_back({t, Eigen::Vector3d(1 + 0.2 * u(rng), 1 + 0.2 * u(rng), 1)});
    if (kind == 1) tr.scale.push_back({0.7, Eigen::Vector3d(2, 2, 2)});
  }
  return clip;
}

double Difference(const LocalPose& a, const LocalPose& b, int j) {
  return std::max({(a.rigid[j].real().coeffs() - b.rigid[j].real().coeffs()).cwiseAbs().maxCoeff(),
                   (a.rigid[j].dual().coeffs() - b.rigid[j].dual().coeffs()).cwiseAbs().maxCoeff(),
                   (a.scale[j] - b.scale[j]).cwiseAbs().maxCoeff()});
}

// The largest coefficient difference from SamplingJob over `times`, looped and clamped.
double LargestDifference(const Skeleton& sk, const Clip& clip, bool nlerp, const std::vector<double>& times) {
  const PreparedClip prepared(sk, clip, nlerp);
  LocalPose a(sk.size()), b(sk.size());
  double worst = 0;
  for (bool loop : {true, false})
    for (double t : times) {
      EXPECT_TRUE((SamplingJob{&sk, &clip, t, loop, &a, nlerp}.Run()));
      EXPECT_TRUE((PreparedSamplingJob{&prepared, t, loop, &b}.Run()));
      for (int j = 0; j < sk.size(); ++j) worst = std::max(worst, Difference(a, b, j));
    }
  return worst;
}

TEST(PreparedClip, SamplesAsSamplingJobOnEveryKindOfChannel) {
  std::mt19937 rng(7);
  const Skeleton sk = MakeSkeleton(rng);
  const Clip clip = MakeClip(rng);
  std::vector<double> times = {-0.5, 0.0, 0.1, 0.25, 0.5, 1.0, 1.5, 1.95, 2.0, 2.5, 7.3};  // keys, ends, outside
  for (int s = 0; s <= 2000; ++s) times.push_back(-1.0 + 5.0 * s / 2000);
  const PreparedClip prepared(sk, clip);
  EXPECT_EQ(prepared.timeline_count(), 3);  // even, uneven, other: searched once each per sample
  const double slerp = LargestDifference(sk, clip, false, times), nlerp = LargestDifference(sk, clip, true, times);
  std::printf("[prepared] synthetic: largest difference from SamplingJob %.2g (slerp), %.2g (nlerp)\n", slerp, nlerp);
  EXPECT_LT(slerp, 1e-13);
  EXPECT_LT(nlerp, 1e-13);
}

TEST(PreparedClip, JointSubsetWritesOnlyItsJoints) {
  std::mt19937 rng(3);
  const Skeleton sk = MakeSkeleton(rng);
  const Clip clip = MakeClip(rng);
  const std::vector<int> joints = {0, 4, 5, 11};
  const PreparedClip prepared(sk, clip, false, joints);
  LocalPose all(sk.size()), part(sk.size());
  ASSERT_TRUE((SamplingJob{&sk, &clip, 0.77, true, &all}.Run()));
  ASSERT_TRUE((PreparedSamplingJob{&prepared, 0.77, true, &part}.Run()));
  for (int j = 0; j < sk.size(); ++j) {
    if (std::find(joints.begin(), joints.end(), j) != joints.end()) {
      EXPECT_LT(Difference(all, part, j), 1e-13) << j;
    } else {
      EXPECT_TRUE(part.rigid[j].real().coeffs() == DualQuatd().real().coeffs()) << j;  // untouched
      EXPECT_TRUE(part.scale[j] == Eigen::Vector3d::Ones()) << j;
    }
  }
}

TEST(PreparedClip, RejectsWhatDoesNotFit) {
  std::mt19937 rng(5);
  const Skeleton sk = MakeSkeleton(rng);
  Clip clip = MakeClip(rng);
  const std::vector<int> out_of_range = {kJoints};
  EXPECT_THROW(PreparedClip(sk, clip, false, out_of_range), Error);
  clip.tracks.pop_back();
  EXPECT_THROW(PreparedClip(sk, clip), Error);
  const Clip fits = MakeClip(rng);
  const PreparedClip prepared(sk, fits);
  LocalPose wrong(3);
  EXPECT_FALSE((PreparedSamplingJob{&prepared, 0.0, true, &wrong}.Run()));
  LocalPose pose(sk.size());
  EXPECT_FALSE((PreparedSamplingJob{&prepared, std::nan(""), true, &pose}.Run()));
  EXPECT_FALSE((PreparedSamplingJob{nullptr, 0.0, true, &pose}.Run()));
}

TEST(PreparedClip, SamplesAsSamplingJobOnTheTestAssets) {
  const std::filesystem::path bcn = "/usr/share/assimp/models/X/BCN_Epileptic.X";
  const std::filesystem::path bvh = "/usr/share/assimp/models/BVH/01_01.bvh";
  ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("characters/Fox"), "../shared/data");
  ARVIEW_REQUIRE_DATA_PATH(bcn, "Debian package assimp-testmodels");
  ARVIEW_REQUIRE_DATA_PATH(bvh, "Debian package assimp-testmodels");
  for (const std::filesystem::path& asset :
       {testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"), testing::SharedData("characters/CesiumMan.glb"), bcn, bvh}) {
    const Character c = authoring::LoadCharacter(asset);
    double slerp = 0, nlerp = 0;
    for (const Clip& clip : c.clips) {
      std::vector<double> times;
      for (int s = 0; s <= 997; ++s) times.push_back(clip.duration * s / 997.0);
      slerp = std::max(slerp, LargestDifference(c.skeleton, clip, false, times));
      nlerp = std::max(nlerp, LargestDifference(c.skeleton, clip, true, times));
    }
    std::printf("[prepared] %s: largest difference from SamplingJob %.2g (slerp), %.2g (nlerp)\n", asset.filename().c_str(),
                slerp, nlerp);
    EXPECT_LT(slerp, 1e-13) << asset;
    EXPECT_LT(nlerp, 1e-13) << asset;
  }
}

}  // namespace
}  // namespace arview::anim
