// Morph targets in the runtime: building them in code, checking them, sampling weight tracks,
// blending them in the schedule, and the animator's frame and face-layer write.

#include "anim/animator.h"
#include "anim/blendable.h"
#include "anim/morph.h"
#include "anim/schedule.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

namespace arview::anim {
namespace {

// One joint, one quad (4 vertices) facing +z, no targets yet.
Character Quad() {
  Character c;
  c.source = "quad.test";
  c.skeleton.names = {"root"};
  c.skeleton.parents = {-1};
  c.skeleton.rest = {Transform{}};
  c.skeleton.inverse_bind = {Eigen::Matrix4d::Identity()};
  Mesh m;
  m.name = "face";
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.normals.assign(4, Eigen::Vector3f::UnitZ());
  m.indices = {0, 1, 2, 0, 2, 3};
  m.joints.assign(4, {0, 0, 0, 0});
  m.weights.assign(4, Eigen::Vector4f(1, 0, 0, 0));
  c.meshes.push_back(m);
  return c;
}

std::vector<Eigen::Vector3f> Deltas(std::initializer_list<Eigen::Vector3f> d) { return d; }

// "lift" raises vertices 2 and 3; "push" moves vertex 0 along z.
Character QuadWithTargets() {
  Character c = Quad();
  AddMorphTarget(c, "lift", 0, Deltas({{0, 0, 0}, {0, 0, 0}, {0, 0.5f, 0}, {0, 0.5f, 0}}));
  AddMorphTarget(c, "push", 0, Deltas({{0, 0, 1}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}),
                 Deltas({{0, 0.1f, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}));
  return c;
}

// A clip with no joint motion and one weight track: 0 at t = 0, 1 at t = 1.
std::shared_ptr<Clip> Ramp(const Skeleton& sk, int target, double to = 1.0) {
  auto clip = std::make_shared<Clip>();
  clip->name = "ramp" + std::to_string(target);
  clip->duration = 1;
  clip->tracks.resize(sk.size());
  clip->weight_tracks.push_back({target, {{0.0, 0.0}, {1.0, to}}});
  return clip;
}

TEST(MorphTargets, AddStoresOnlyTheMovedVerticesAndNamesTheTarget) {
  const Character c = QuadWithTargets();
  ASSERT_EQ(c.skeleton.morph_target_count(), 2);
  EXPECT_EQ(c.skeleton.FindMorphTarget("lift"), 0);
  EXPECT_EQ(c.skeleton.FindMorphTarget("push"), 1);
  EXPECT_EQ(c.skeleton.FindMorphTarget("blink"), -1);
  ASSERT_EQ(c.meshes[0].morphs.size(), 2u);
  EXPECT_EQ(c.meshes[0].morphs[0].vertices, (std::vector<std::uint32_t>{2, 3}));
  EXPECT_EQ(c.meshes[0].morphs[1].vertices, (std::vector<std::uint32_t>{0}));
  EXPECT_TRUE(c.meshes[0].morphs[1].normal_deltas[0].isApprox(Eigen::Vector3f(0, 0.1f, 0)));
  EXPECT_NO_THROW(CheckMorphTargets(c));
}

TEST(MorphTargets, ATargetNamedAgainOnAnotherMeshIsTheSameTarget) {
  Character c = QuadWithTargets();
  c.meshes.push_back(c.meshes[0]);
  c.meshes[1].morphs.clear();
  EXPECT_EQ(AddMorphTarget(c, "lift", 1, Deltas({{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 1, 0}})), 0);
  EXPECT_EQ(c.skeleton.morph_target_count(), 2);
  EXPECT_NO_THROW(CheckMorphTargets(c));
}

void ExpectErrorNaming(const std::function<void()>& f, const std::string& a, const std::string& b) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(a), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(b), std::string::npos) << e.what();
  }
}

TEST(MorphTargets, BuildingRefusesWrongCountsNonFiniteDeltasAndRepeats) {
  Character c = QuadWithTargets();
  ExpectErrorNaming([&] { AddMorphTarget(c, "short", 0, Deltas({{0, 0, 0}})); }, "quad.test", "'short'");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  ExpectErrorNaming([&] { AddMorphTarget(c, "bad", 0, Deltas({{0, 0, 0}, {nan, 0, 0}, {0, 0, 0}, {0, 0, 0}})); },
                    "quad.test", "'bad'");
  ExpectErrorNaming([&] { AddMorphTarget(c, "lift", 0, Deltas({{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 1, 0}})); },
                    "quad.test", "'lift'");
  ExpectErrorNaming([&] { AddMorphTarget(c, "elsewhere", 3, Deltas({})); }, "quad.test", "'elsewhere'");
  EXPECT_EQ(c.skeleton.morph_target_count(), 2) << "a refused target is not added";
}

TEST(MorphTargets, CheckNamesTheAssetAndTheTarget) {
  {
    Character c = QuadWithTargets();
    c.clips.push_back(*Ramp(c.skeleton, 2));
    ExpectErrorNaming([&] { CheckMorphTargets(c); }, "quad.test", "weight track for a target the character does not have");
  }
  {
    Character c = QuadWithTargets();
    c.meshes[0].morphs[0].position_deltas[1].y() = std::numeric_limits<float>::infinity();
    ExpectErrorNaming([&] { CheckMorphTargets(c); }, "quad.test: morph target 'lift'", "non-finite");
  }
  {
    Character c = QuadWithTargets();
    c.meshes[0].morphs[1].vertices[0] = 4;
    ExpectErrorNaming([&] { CheckMorphTargets(c); }, "morph target 'push'", "out of range");
  }
  {
    Character c = QuadWithTargets();
    c.skeleton.morph_targets[1] = "lift";
    ExpectErrorNaming([&] { CheckMorphTargets(c); }, "morph target 'lift'", "two targets");
  }
}

TEST(MorphTargets, ApplyAddsTheWeightedDeltas) {
  const Character c = QuadWithTargets();
  std::vector<Eigen::Vector3f> p, n;
  const std::vector<float> w{0.5f, -1.f};
  ApplyMorphTargets(c.meshes[0], w, p, n);
  EXPECT_TRUE(p[0].isApprox(Eigen::Vector3f(0, 0, -1)));
  EXPECT_TRUE(p[2].isApprox(Eigen::Vector3f(1, 1.25f, 0)));
  EXPECT_TRUE(n[0].isApprox(Eigen::Vector3f(0, -0.1f, 1)));
  ApplyMorphTargets(c.meshes[0], {}, p, n);
  EXPECT_EQ(p, c.meshes[0].positions);
}

TEST(MorphTargets, WeightTracksSampleLinearlyAndPreparedSamplingAgrees) {
  Character c = QuadWithTargets();
  Clip clip = *Ramp(c.skeleton, 1, 0.8);
  clip.duration = 2;
  clip.weight_tracks.push_back({0, {{0.5, 1.0}}});  // one key: held
  LocalPose direct = LocalPose::Rest(c.skeleton), prepared_pose = LocalPose::Rest(c.skeleton);
  const PreparedClip prepared(c.skeleton, clip);
  for (double t : {0.0, 0.25, 0.5, 1.0, 1.7}) {
    ASSERT_TRUE((SamplingJob{&c.skeleton, &clip, t, /*loop=*/false, &direct}.Run()));
    ASSERT_TRUE((PreparedSamplingJob{&prepared, t, /*loop=*/false, &prepared_pose}.Run()));
    EXPECT_TRUE(direct.morph_keyed);
    EXPECT_FLOAT_EQ(direct.morph[1], static_cast<float>(0.8 * std::min(t, 1.0))) << t;
    EXPECT_FLOAT_EQ(direct.morph[0], 1.f);
    EXPECT_EQ(direct.morph, prepared_pose.morph);
  }
  LocalPose joints_only(c.skeleton.size());
  EXPECT_TRUE((PreparedSamplingJob{&prepared, 0.5, false, &joints_only}.Run())) << "a pose without weights samples joints";
  EXPECT_FALSE(joints_only.morph_keyed);
  LocalPose wrong(c.skeleton.size(), 3);
  EXPECT_FALSE((PreparedSamplingJob{&prepared, 0.5, false, &wrong}.Run()));
  Clip missing = clip;
  missing.weight_tracks[0].target = 5;
  EXPECT_THROW(PreparedClip(c.skeleton, missing), Error);
}

struct Rig {
  Character c = QuadWithTargets();
  std::shared_ptr<const Skeleton> sk = std::make_shared<Skeleton>(c.skeleton);
};

TEST(MorphTargets, TheScheduleBlendsWeightsOfTheActionsThatKeyThem) {
  Rig rig;
  Schedule s(rig.sk);
  LocalPose out = LocalPose::Rest(*rig.sk);
  auto lift = std::make_shared<ClipSource>(rig.sk, Ramp(*rig.sk, 0));
  auto push = std::make_shared<ClipSource>(rig.sk, Ramp(*rig.sk, 1));
  auto still = std::make_shared<StaticPose>(LocalPose::Rest(*rig.sk));
  s.Add({still, {}, 0, true, "idle"});
  ASSERT_TRUE(s.Sample(0.5, {}, out));
  EXPECT_FALSE(out.morph_keyed) << "nothing keys the face";
  EXPECT_EQ(out.morph, (std::vector<float>{0, 0}));

  s.Add({lift, {}, 0, true, "lift"});
  ASSERT_TRUE(s.Sample(0.5, {}, out));
  EXPECT_TRUE(out.morph_keyed);
  EXPECT_FLOAT_EQ(out.morph[0], 0.5f) << "the idle keys no weights: the clip's stand alone";

  s.Add({push, {}, 0, true, "push"});
  ASSERT_TRUE(s.Sample(0.5, {}, out));
  EXPECT_FLOAT_EQ(out.morph[0], 0.25f) << "two keyed actions of one layer share it";
  EXPECT_FLOAT_EQ(out.morph[1], 0.25f);

  // A layer above at weight 1 replaces the face below.
  auto top = std::make_shared<ClipSource>(rig.sk, Ramp(*rig.sk, 1, 0.4));
  const int id = s.Add({top, {}, 0, true, "top", 1});
  ASSERT_TRUE(s.Sample(1.0, {}, out));
  EXPECT_FLOAT_EQ(out.morph[0], 0.f);
  EXPECT_FLOAT_EQ(out.morph[1], 0.4f);
  ASSERT_TRUE(s.SetLiveWeight(id, 0.25));
  ASSERT_TRUE(s.Sample(1.0, {}, out));
  EXPECT_FLOAT_EQ(out.morph[0], 0.75f * 0.5f);
  EXPECT_FLOAT_EQ(out.morph[1], 0.75f * 0.5f + 0.25f * 0.4f);
}

TEST(MorphTargets, TheAnimatorCarriesTheWeightsAndAFaceLayerCanSetThem) {
  Rig rig;
  auto s = std::make_shared<Schedule>(rig.sk);
  s->Add({std::make_shared<ClipSource>(rig.sk, Ramp(*rig.sk, 1)), {}, 0, true, "ramp"});
  Animator animator(rig.sk, s);
  const AnimatorFrame& f = animator.Update(0.25, {});
  ASSERT_EQ(f.morph_weights.size(), 2u);
  EXPECT_FLOAT_EQ(f.morph_weights[0], 0.f);
  EXPECT_FLOAT_EQ(f.morph_weights[1], 0.25f);
  EXPECT_TRUE(animator.SetMorphWeight(0, 0.9f));
  EXPECT_FLOAT_EQ(f.morph_weights[0], 0.9f);
  EXPECT_FALSE(animator.SetMorphWeight(2, 1.f));
  EXPECT_FALSE(animator.SetMorphWeight(-1, 1.f));
  EXPECT_FALSE(animator.SetMorphWeight(1, std::numeric_limits<float>::quiet_NaN()));
  EXPECT_FLOAT_EQ(f.morph_weights[1], 0.25f);
  animator.Update(0.5, {});
  EXPECT_FLOAT_EQ(f.morph_weights[0], 0.f) << "the next frame starts again from the clips";
  EXPECT_FLOAT_EQ(f.morph_weights[1], 0.5f);
}

TEST(MorphTargets, ACharacterWithoutTargetsHasNoWeights) {
  const Character c = Quad();
  auto sk = std::make_shared<const Skeleton>(c.skeleton);
  auto s = std::make_shared<Schedule>(sk);
  s->Add({std::make_shared<StaticPose>(LocalPose::Rest(*sk)), {}, 0, true, "idle"});
  Animator animator(sk, s);
  EXPECT_TRUE(animator.Update(0, {}).morph_weights.empty());
  EXPECT_FALSE(animator.SetMorphWeight(0, 1.f));
}

}  // namespace
}  // namespace arview::anim
