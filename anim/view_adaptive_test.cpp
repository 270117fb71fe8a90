// ViewAdaptiveBlend samples the joints on which every key clip agrees once and blends only the
// others; its pose must be the blend of every key sampled in full (SamplingJob + BlendingJob)
// to rounding, with DLB and DIB, whether keys share joints, share none (clips of different
// lengths) or share them all.

#include "anim/view_adaptive.h"

#include <gtest/gtest.h>

#include <random>

namespace arview::anim {
namespace {

constexpr int kJoints = 10;

std::shared_ptr<const Skeleton> MakeSkeleton() {
  auto sk = std::make_shared<Skeleton>();
  for (int j = 0; j < kJoints; ++j) {
    sk->names.push_back("j" + std::to_string(j));
    sk->parents.push_back(j - 1);
    Transform t;
    t.translation = Eigen::Vector3d(0, 0.1 * j, 0);
    sk->rest.push_back(t);
    sk->inverse_bind.push_back(Eigen::Matrix4d::Identity());
  }
  return sk;
}

Eigen::Quaterniond Random(std::mt19937& rng, double angle) {
  std::uniform_real_distribution<double> u(-1, 1);
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
}

// A clip of `keys` keys per joint over `duration` seconds.
Clip MakeClip(std::mt19937& rng, double duration, int keys) {
  Clip c;
  c.name = "base";
  c.duration = duration;
  c.tracks.resize(kJoints);
  for (int j = 0; j < kJoints; ++j)
    for (int i = 0; i < keys; ++i) {
      const double t = duration * i / (keys - 1);
      c.tracks[j].rotation.push_back({t, Random(rng, 1.0)});
      c.tracks[j].translation.push_back({t, Eigen::Vector3d(0.01 * i, 0.1 * j, 0)});
    }
  return c;
}

// Keys every 45° round the character; key k's clip is `base` with joints 2, 3 and 7 turned
// differently (as generated look-at keys differ from their base clip in the chain only).
std::vector<ViewAdaptiveKey> MakeKeys(std::mt19937& rng, const Clip& base) {
  std::vector<ViewAdaptiveKey> keys;
  for (int k = 0; k < 8; ++k) {
    Clip c = base;
    for (int j : {2, 3, 7})
      for (auto& key : c.tracks[j].rotation) key.value = (Random(rng, 0.5) * key.value).normalized();
    const double a = k * M_PI / 4;
    keys.push_back({Eigen::Vector3d(std::sin(a), 0, std::cos(a)), std::make_shared<const Clip>(std::move(c))});
  }
  return keys;
}

// The largest coefficient difference between the blend and every key sampled in full and
// blended, over viewpoints round the character and times across two loops.
double LargestDifference(const std::shared_ptr<const Skeleton>& sk, const std::vector<ViewAdaptiveKey>& keys, BlendMethod method) {
  ViewAdaptiveOptions options;
  options.blend = method;
  options.phase = PhaseMode::kIndependent;  // each key at t (their lengths may differ)
  ViewAdaptiveBlend blend(sk, keys, options);
  std::vector<LocalPose> poses(keys.size(), LocalPose(kJoints));
  LocalPose fast(kJoints), full(kJoints);
  double worst = 0;
  for (int s = 0; s < 200; ++s) {
    const double t = 0.037 * s;
    const double azimuth = 0.1 * s;
    FrameInputs in;
    in.viewpoint = Eigen::Vector3d(std::sin(azimuth), 0.2, std::cos(azimuth)).normalized();
    EXPECT_TRUE(blend.Sample(t, in, fast));
    std::vector<const LocalPose*> ptrs;
    std::vector<double> ws;
    for (std::size_t k = 0; k < keys.size(); ++k) {
      if (blend.weights()[k] <= 0) continue;
      EXPECT_TRUE((SamplingJob{sk.get(), keys[k].clip.get(), t, true, &poses[k]}.Run()));
      ptrs.push_back(&poses[k]);
      ws.push_back(blend.weights()[k]);
    }
    BlendingJob job;
    job.inputs = ptrs;
    job.weights = ws;
    job.method = method;
    job.output = &full;
    EXPECT_TRUE(job.Run());
    for (int j = 0; j < kJoints; ++j)
      worst = std::max({worst, (fast.rigid[j].real().coeffs() - full.rigid[j].real().coeffs()).cwiseAbs().maxCoeff(),
                        (fast.rigid[j].dual().coeffs() - full.rigid[j].dual().coeffs()).cwiseAbs().maxCoeff(),
                        (fast.scale[j] - full.scale[j]).cwiseAbs().maxCoeff()});
  }
  return worst;
}

TEST(ViewAdaptiveBlend, JointsSharedByEveryKeyAreSampledOnceWithTheSamePose) {
  std::mt19937 rng(11);
  const auto sk = MakeSkeleton();
  const Clip base = MakeClip(rng, 2.0, 21);
  const std::vector<ViewAdaptiveKey> keys = MakeKeys(rng, base);
  EXPECT_LT(LargestDifference(sk, keys, BlendMethod::kDlb), 1e-12);
  EXPECT_LT(LargestDifference(sk, keys, BlendMethod::kDib), 1e-12);
}

TEST(ViewAdaptiveBlend, KeysOfDifferentLengthsShareNoJoint) {
  std::mt19937 rng(12);
  const auto sk = MakeSkeleton();
  const Clip base = MakeClip(rng, 2.0, 21);
  std::vector<ViewAdaptiveKey> keys = MakeKeys(rng, base);
  Clip longer = *keys[3].clip;
  longer.duration = 2.5;  // same keys, another loop length: sampled at other times
  keys[3].clip = std::make_shared<const Clip>(std::move(longer));
  EXPECT_LT(LargestDifference(sk, keys, BlendMethod::kDlb), 1e-12);
  EXPECT_LT(LargestDifference(sk, keys, BlendMethod::kDib), 1e-12);
}

TEST(ViewAdaptiveBlend, KeysThatAgreeEverywhereGiveTheirClip) {
  std::mt19937 rng(13);
  const auto sk = MakeSkeleton();
  const auto clip = std::make_shared<const Clip>(MakeClip(rng, 1.5, 11));
  std::vector<ViewAdaptiveKey> keys;
  for (int k = 0; k < 4; ++k) keys.push_back({Eigen::Vector3d(std::sin(k * M_PI / 2), 0, std::cos(k * M_PI / 2)), clip});
  EXPECT_LT(LargestDifference(sk, keys, BlendMethod::kDlb), 1e-12);
  EXPECT_LT(LargestDifference(sk, keys, BlendMethod::kDib), 1e-12);
}

}  // namespace
}  // namespace arview::anim
