// ViewAdaptiveBlend samples the joints on which every key clip agrees once and blends only the
// others; its pose must be the blend of every key sampled in full (SamplingJob + BlendingJob)
// to rounding, with DLB and DIB, whether keys share joints, share none (clips of different
// lengths) or share them all. The keys' morph target weights are blended with the same weights,
// and a mirrored blend exchanges the left and right targets.

#include "anim/view_adaptive.h"

#include "anim/blendable.h"

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


// The face: the skeleton with three targets, each key keying them differently (or not at all).
const std::vector<std::string> kTargets = {"eyeBlinkLeft", "eyeBlinkRight", "jawOpen"};

std::shared_ptr<const Skeleton> MakeFacedSkeleton() {
  auto sk = std::make_shared<Skeleton>(*MakeSkeleton());
  sk->morph_targets = kTargets;
  return sk;
}

// Key k: eyeBlinkLeft ramps from 0 to k/8 over the clip, eyeBlinkRight is 1 - k/8, jawOpen is
// keyed only on even keys; key 5 has no weight tracks (its face is the rest).
std::vector<ViewAdaptiveKey> WithFaces(const std::vector<ViewAdaptiveKey>& keys) {
  std::vector<ViewAdaptiveKey> faced;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    Clip c = *keys[k].clip;
    const double w = k / 8.0;
    if (k != 5) {
      c.weight_tracks.push_back({0, {{0.0, 0.0}, {c.duration, w}}});
      c.weight_tracks.push_back({1, {{0.0, 1 - w}}});
      if (k % 2 == 0) c.weight_tracks.push_back({2, {{0.0, 0.1 * k}, {0.5 * c.duration, 0.0}}});
    }
    faced.push_back({keys[k].viewpoint, std::make_shared<const Clip>(std::move(c))});
  }
  return faced;
}

FrameInputs Around(double azimuth) {
  FrameInputs in;
  in.viewpoint = Eigen::Vector3d(std::sin(azimuth), 0.2, std::cos(azimuth)).normalized();
  return in;
}

TEST(ViewAdaptiveFace, TheKeysWeightsAreBlendedWithTheirViewWeights) {
  std::mt19937 rng(14);
  const auto sk = MakeFacedSkeleton();
  const std::vector<ViewAdaptiveKey> keys = WithFaces(MakeKeys(rng, MakeClip(rng, 2.0, 21)));
  ViewAdaptiveOptions options;
  options.phase = PhaseMode::kIndependent;
  ViewAdaptiveBlend blend(sk, keys, options);
  LocalPose out(kJoints, 3), key_pose(kJoints, 3);
  double worst = 0, largest = 0;
  for (int s = 0; s < 200; ++s) {
    const double t = 0.037 * s;
    ASSERT_TRUE(blend.Sample(t, Around(0.1 * s), out));
    ASSERT_TRUE(out.morph_keyed);
    std::vector<double> expected(3, 0.0);
    double total = 0;
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const double w = blend.weights()[k];
      total += w;
      if (w <= 0 || keys[k].clip->weight_tracks.empty()) continue;
      ASSERT_TRUE((SamplingJob{sk.get(), keys[k].clip.get(), t, true, &key_pose}.Run()));
      for (int i = 0; i < 3; ++i) expected[i] += w * key_pose.morph[i];
    }
    for (int i = 0; i < 3; ++i) {
      worst = std::max(worst, std::abs(out.morph[i] - expected[i] / total));
      largest = std::max(largest, static_cast<double>(out.morph[i]));
    }
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(largest, 0.3) << "the keys' weights reach the pose";
}

TEST(ViewAdaptiveFace, KeysWithOneFaceGiveItAndKeysWithoutLeaveTheFaceUnkeyed) {
  std::mt19937 rng(15);
  const auto sk = MakeFacedSkeleton();
  const Clip base = MakeClip(rng, 2.0, 21);
  const std::vector<ViewAdaptiveKey> plain = MakeKeys(rng, base);
  std::vector<ViewAdaptiveKey> same;
  Clip smiling = base;
  smiling.weight_tracks.push_back({2, {{0.0, 0.2}, {2.0, 0.9}}});
  for (const ViewAdaptiveKey& k : plain) {
    Clip c = *k.clip;
    c.weight_tracks = smiling.weight_tracks;
    same.push_back({k.viewpoint, std::make_shared<const Clip>(std::move(c))});
  }
  ViewAdaptiveBlend one_face(sk, same), no_face(sk, plain);
  LocalPose out(kJoints, 3), reference(kJoints, 3);
  for (int s = 0; s < 50; ++s) {
    const double t = 0.09 * s;
    ASSERT_TRUE(one_face.Sample(t, Around(0.3 * s), out));
    ASSERT_TRUE(out.morph_keyed);
    // The shared phase: every key at the same place in its clip (all 2 s long): t looped.
    ASSERT_TRUE((SamplingJob{sk.get(), &smiling, t, true, &reference}.Run()));
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(out.morph[i], reference.morph[i], 1e-6) << "t " << t << " target " << i;
    out.morph_keyed = true;
    ASSERT_TRUE(no_face.Sample(t, Around(0.3 * s), out));
    EXPECT_FALSE(out.morph_keyed);
  }
}

TEST(ViewAdaptiveFace, AMirroredBlendExchangesTheLeftAndRightTargets) {
  Skeleton named = *MakeFacedSkeleton();
  named.morph_targets = {"eyeBlinkLeft", "mouthSmileRight", "jawOpen", "eyeBlinkRight", "mouthSmileLeft", "viseme_RR"};
  EXPECT_EQ(MirrorTargetPartners(named), (std::vector<int>{3, 4, 2, 0, 1, 5}));
  std::mt19937 rng(16);
  const auto sk = MakeFacedSkeleton();
  const std::vector<ViewAdaptiveKey> keys = WithFaces(MakeKeys(rng, MakeClip(rng, 2.0, 21)));
  auto blend = std::make_shared<ViewAdaptiveBlend>(sk, keys);
  Mirror mirror(blend, sk);
  LocalPose direct(kJoints, 3), mirrored(kJoints, 3);
  for (int s = 0; s < 50; ++s) {
    ASSERT_TRUE(mirror.Sample(0.07 * s, Around(0.2 * s), mirrored));
    ASSERT_TRUE(blend->Sample(0.07 * s, Around(0.2 * s), direct));
    ASSERT_TRUE(mirrored.morph_keyed);
    EXPECT_EQ(mirrored.morph[0], direct.morph[1]);
    EXPECT_EQ(mirrored.morph[1], direct.morph[0]);
    EXPECT_EQ(mirrored.morph[2], direct.morph[2]);
  }
}

}  // namespace
}  // namespace arview::anim
