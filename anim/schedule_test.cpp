// The MIRAnim engine on a small synthetic humanoid: curves, masks and scopes, the frame
// blender, schedules (nested, edited while running), modifiers, and continuity during fades.

#include "anim/blendable.h"
#include "anim/blending_params.h"
#include "anim/schedule.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arview::anim {
namespace {

// Hips → legs, spine → chest → arms, neck → head.
std::shared_ptr<Skeleton> Humanoid() {
  auto sk = std::make_shared<Skeleton>();
  auto add = [&](const std::string& name, int parent, Eigen::Vector3d offset) {
    sk->names.push_back(name);
    sk->parents.push_back(parent);
    Transform t;
    t.translation = offset;
    // A rest rotation per joint, not symmetric, so that the mirror has something to correct.
    t.rotation = Eigen::AngleAxisd(0.05 * static_cast<double>(sk->names.size()), Eigen::Vector3d(0.3, 1, 0.2).normalized());
    sk->rest.push_back(t);
    sk->inverse_bind.push_back(Eigen::Matrix4d::Identity());
    return static_cast<int>(sk->names.size()) - 1;
  };
  const int hips = add("Hips", -1, {0, 1, 0});
  const int lul = add("LeftUpLeg", hips, {0.1, 0, 0});
  add("LeftLeg", lul, {0, -0.45, 0});
  const int rul = add("RightUpLeg", hips, {-0.1, 0, 0});
  add("RightLeg", rul, {0, -0.45, 0});
  const int spine = add("Spine", hips, {0, 0.1, 0});
  const int chest = add("Chest", spine, {0, 0.2, 0});
  const int ls = add("LeftShoulder", chest, {0.15, 0.1, 0});
  const int la = add("LeftArm", ls, {0.1, 0, 0});
  add("LeftHand", la, {0.25, 0, 0});
  const int rs = add("RightShoulder", chest, {-0.15, 0.1, 0});
  const int ra = add("RightArm", rs, {-0.1, 0, 0});
  add("RightHand", ra, {-0.25, 0, 0});
  const int neck = add("Neck", chest, {0, 0.15, 0});
  add("Head", neck, {0, 0.1, 0});
  return sk;
}

// A smooth clip: every joint rotates sinusoidally about its own axis, keys at 30 Hz; the root
// also moves.
std::shared_ptr<Clip> Wave(const Skeleton& sk, unsigned seed, double duration, double amplitude) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  auto clip = std::make_shared<Clip>();
  clip->name = "wave" + std::to_string(seed);
  clip->duration = duration;
  clip->tracks.resize(sk.size());
  for (int j = 0; j < sk.size(); ++j) {
    const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double phase = 3 * u(rng), freq = u(rng) < 0 ? 1 : 2;  // whole periods: loops without a seam
    for (int i = 0; i <= static_cast<int>(std::round(duration * 30)); ++i) {
      const double t = i / 30.0;
      const double angle = amplitude * std::sin(2 * M_PI * freq * t / duration + phase);
      clip->tracks[j].rotation.push_back({t, sk.rest[j].rotation * Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis))});
      if (j == 0) clip->tracks[j].translation.push_back({t, sk.rest[j].translation + Eigen::Vector3d(0.1 * std::sin(t), 0, 0)});
    }
  }
  return clip;
}

LocalPose Sampled(Blendable& b, double t, int joints) {
  LocalPose p(joints);
  EXPECT_TRUE(b.Sample(t, {}, p));
  return p;
}

LocalPose SampledClip(const Skeleton& sk, const Clip& clip, double t) {
  LocalPose p(sk.size());
  EXPECT_TRUE((SamplingJob{&sk, &clip, t, false, &p}.Run()));
  return p;
}

double RotationAngle(const DualQuatd& a, const DualQuatd& b) {
  return a.Rotation().angularDistance(b.Rotation());
}

void ExpectSamePose(const LocalPose& a, const LocalPose& b, double tolerance, const std::string& what) {
  ASSERT_EQ(a.size(), b.size());
  for (int j = 0; j < a.size(); ++j) {
    EXPECT_LT(RotationAngle(a.rigid[j], b.rigid[j]), tolerance) << what << " joint " << j;
    EXPECT_LT((a.rigid[j].Translation() - b.rigid[j].Translation()).norm(), tolerance) << what << " joint " << j;
  }
}

TEST(Curve, ValuesAtKnownTimes) {
  const double L = 10;
  const Curve lin = Curve::LinearFade(0.2, 0.2);  // 2 s in, 2 s out
  EXPECT_DOUBLE_EQ(lin.Value(0, L), 0);
  EXPECT_DOUBLE_EQ(lin.Value(1, L), 0.5);
  EXPECT_DOUBLE_EQ(lin.Value(2, L), 1);
  EXPECT_DOUBLE_EQ(lin.Value(5, L), 1);
  EXPECT_DOUBLE_EQ(lin.Value(9, L), 0.5);
  EXPECT_DOUBLE_EQ(lin.Value(10, L), 0);
  EXPECT_DOUBLE_EQ(lin.Value(-1, L), 0);
  EXPECT_DOUBLE_EQ(lin.Value(11, L), 0);
  const Curve cos = Curve::CosineFade(0.2, 0.2);
  EXPECT_NEAR(cos.Value(1, L), 0.5, 1e-12);
  EXPECT_NEAR(cos.Value(0.5, L), (1 - std::cos(M_PI / 4)) / 2, 1e-12);
  EXPECT_NEAR(cos.Value(9.5, L), (1 - std::cos(M_PI / 4)) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(cos.Value(5, L), 1);
  // Cosine ramps start and end flat: tiny slope near the ends.
  EXPECT_LT(cos.Value(0.01, L), 1e-4);
  const Curve adsr = Curve::Adsr(0.1, 0.1, 0.5, 0.2);  // attack 1 s, decay 1 s to 0.5, release 2 s
  EXPECT_DOUBLE_EQ(adsr.Value(0.5, L), 0.5);
  EXPECT_DOUBLE_EQ(adsr.Value(1, L), 1);
  EXPECT_DOUBLE_EQ(adsr.Value(1.5, L), 0.75);
  EXPECT_DOUBLE_EQ(adsr.Value(3, L), 0.5);
  EXPECT_DOUBLE_EQ(adsr.Value(9, L), 0.25);
  EXPECT_DOUBLE_EQ(adsr.Value(10, L), 0);
  const Curve cadsr = Curve::Adsr(0.1, 0.1, 0.5, 0.2, /*cosine=*/true);
  EXPECT_NEAR(cadsr.Value(0.5, L), 0.5, 1e-12);
  EXPECT_NEAR(cadsr.Value(1.25, L), 1 - 0.5 * (1 - std::cos(M_PI / 4)) / 2, 1e-12);
  EXPECT_NEAR(cadsr.Value(9, L), 0.25, 1e-12);
  // Unbounded actions take lengths in seconds and never fade out.
  Curve in2 = Curve::CosineFade(2, 0);
  in2.in_seconds = true;
  EXPECT_NEAR(in2.Value(1, kUnbounded), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(in2.Value(1e6, kUnbounded), 1);
  EXPECT_EQ(in2.Check(kUnbounded), "");
  EXPECT_NE(Curve::CosineFade(0.2, 0.2).Check(kUnbounded), "");
  EXPECT_NE(Curve::LinearFade(0.7, 0.5).Check(10), "");
  EXPECT_NE(Curve::Adsr(0.1, 0.1, 1.5, 0.1).Check(10), "");
  EXPECT_DOUBLE_EQ(Curve::Constant(0.3).Value(4, L), 0.3);
}

TEST(Scopes, ResolvedFromTheSkeletonByName) {
  const auto sk = Humanoid();
  auto names = [&](const std::vector<int>& js) {
    std::vector<std::string> n;
    for (int j : js) n.push_back(sk->names[j]);
    return n;
  };
  using V = std::vector<std::string>;
  EXPECT_EQ(names(ResolveScope(*sk, "legs")), (V{"LeftUpLeg", "LeftLeg", "RightUpLeg", "RightLeg"}));
  EXPECT_EQ(names(ResolveScope(*sk, "left_arm")), (V{"LeftShoulder", "LeftArm", "LeftHand"}));
  EXPECT_EQ(names(ResolveScope(*sk, "right_arm")), (V{"RightShoulder", "RightArm", "RightHand"}));
  EXPECT_EQ(names(ResolveScope(*sk, "head")), (V{"Neck", "Head"}));
  EXPECT_EQ(ResolveScope(*sk, "torso").size(), 10u);  // spine, chest, both arms, neck, head
  EXPECT_EQ(names(ResolveScope(*sk, "root")), (V{"Hips"}));
  ScopeTable custom{{"hands", {{"LeftHand", "RightHand"}, true}}, {"spine_only", {{"Spine"}, false}}};
  EXPECT_EQ(names(ResolveScope(*sk, "hands", custom)), (V{"LeftHand", "RightHand"}));
  EXPECT_EQ(names(ResolveScope(*sk, "spine_only", custom)), (V{"Spine"}));
  EXPECT_THROW(ResolveScope(*sk, "tail"), Error);
  ScopeTable bad{{"x", {{"Nope"}, true}}};
  EXPECT_THROW(ResolveScope(*sk, "x", bad), Error);
}

TEST(Mirror, PartnersByName) {
  const auto sk = Humanoid();
  const std::vector<int> p = MirrorPartners(*sk);
  EXPECT_EQ(sk->names[p[sk->Find("LeftArm")]], "RightArm");
  EXPECT_EQ(sk->names[p[sk->Find("RightUpLeg")]], "LeftUpLeg");
  EXPECT_EQ(sk->names[p[sk->Find("Spine")]], "Spine");
  Skeleton other;
  other.names = {"B_Hand_Left", "B_Hand_Right", "lhumerus", "rhumerus", "LThumb", "RThumb", "arm.L", "arm.R", "Body"};
  other.parents.assign(other.names.size(), -1);
  const std::vector<int> q = MirrorPartners(other);
  EXPECT_EQ(q, (std::vector<int>{1, 0, 2, 3, 5, 4, 7, 6, 8}));  // CMU's "lhumerus" is not recognised: kept
}

class Engine : public ::testing::Test {
 protected:
  std::shared_ptr<Skeleton> sk_ = Humanoid();
  int n_ = sk_->size();
  std::shared_ptr<Clip> idle_clip_ = Wave(*sk_, 1, 4.0, 0.2);
  std::shared_ptr<Clip> gesture_clip_ = Wave(*sk_, 2, 2.0, 0.8);
  BlendablePtr idle_ = std::make_shared<ClipSource>(sk_, idle_clip_);
  BlendablePtr gesture_ = std::make_shared<ClipSource>(sk_, gesture_clip_);
};

TEST_F(Engine, OneActionPlaysItsObject) {
  Schedule s(sk_);
  s.Add({idle_, {}, 0.0, false, "idle"});
  for (double t : {0.0, 0.7, 3.9}) ExpectSamePose(Sampled(s, t, n_), SampledClip(*sk_, *idle_clip_, t), 1e-12, "idle");
  EXPECT_DOUBLE_EQ(s.Duration(), 4.0);
}

// Thesis appendix C example 3: the idle with the torso at 0.1, a gesture on the torso only.
TEST_F(Engine, TorsoMaskLeavesTheLegsExactlyAtTheLayerBelow) {
  const std::vector<int> torso = ResolveScope(*sk_, "torso");
  BlendingParams idle_params, gesture_params;
  JointMask idle_mask = JointMask::Uniform(n_, 1.0);
  idle_mask.Set(torso, 0.1);
  idle_params.masks = {idle_mask};
  JointMask gesture_mask = JointMask::Uniform(n_, 0.0);
  gesture_mask.Set(torso, 1.0);
  gesture_params.masks = {gesture_mask};
  Schedule s(sk_);
  s.Add({idle_, idle_params, 0.0, true, "idle"});
  s.Add({gesture_, gesture_params, 1.0, false, "gesture"});
  for (double t : {1.3, 2.2, 2.9}) {
    const LocalPose out = Sampled(s, t, n_);
    const LocalPose idle = SampledClip(*sk_, *idle_clip_, t);
    const LocalPose gesture = SampledClip(*sk_, *gesture_clip_, t - 1.0);
    for (const char* leg : {"Hips", "LeftUpLeg", "LeftLeg", "RightUpLeg", "RightLeg"}) {
      const int j = sk_->Find(leg);
      EXPECT_EQ(out.rigid[j].real().coeffs(), idle.rigid[j].real().coeffs()) << leg;
      EXPECT_EQ(out.rigid[j].dual().coeffs(), idle.rigid[j].dual().coeffs()) << leg;
    }
    // Torso joints: 1/1.1 of the way to the gesture (DLB of two rotations about one point).
    for (int j : torso) {
      const DualQuatd expect = Dlb<double>(std::array<DualQuatd, 2>{idle.rigid[j], gesture.rigid[j]},
                                           std::array<double, 2>{0.1 / 1.1, 1.0 / 1.1});
      EXPECT_LT(RotationAngle(out.rigid[j], expect), 1e-9) << sk_->names[j];
      EXPECT_LT(RotationAngle(out.rigid[j], gesture.rigid[j]), RotationAngle(out.rigid[j], idle.rigid[j]) + 1e-12);
    }
  }
  // Before the gesture starts and after it ends, the whole body plays the idle.
  ExpectSamePose(Sampled(s, 0.5, n_), SampledClip(*sk_, *idle_clip_, 0.5), 1e-12, "before");
  ExpectSamePose(Sampled(s, 3.5, n_), SampledClip(*sk_, *idle_clip_, 3.5), 1e-12, "after");
}

TEST_F(Engine, RotationAndTranslationMasksApart) {
  // The gesture turns the root but leaves its translation to the idle.
  BlendingParams p;
  JointMask m = JointMask::Uniform(n_, 1.0);
  m.SetTranslation({0}, 0.0);
  p.masks = {m};
  Schedule s(sk_);
  s.Add({idle_, {}, 0.0, true, "idle"});
  s.Add({gesture_, p, 0.0, false, "gesture"});
  const LocalPose out = Sampled(s, 1.0, n_);
  const LocalPose idle = SampledClip(*sk_, *idle_clip_, 1.0);
  const LocalPose gesture = SampledClip(*sk_, *gesture_clip_, 1.0);
  EXPECT_LT((out.rigid[0].Translation() - idle.rigid[0].Translation()).norm(), 1e-12);
  const Eigen::Quaterniond half = idle.rigid[0].Rotation().slerp(0.5, gesture.rigid[0].Rotation());
  EXPECT_LT(out.rigid[0].Rotation().angularDistance(half), 1e-3);  // nlerp of two ≈ slerp midpoint
}

TEST_F(Engine, RestPoseBelowTheThreshold) {
  BlendingParams faint;
  faint.gain = 0.02;  // below the 0.1 threshold: rest makes up 0.08
  Schedule s(sk_);
  s.Add({gesture_, faint, 0.0, false, "faint"});
  const LocalPose out = Sampled(s, 0.5, n_);
  const LocalPose g = SampledClip(*sk_, *gesture_clip_, 0.5);
  const LocalPose rest = LocalPose::Rest(*sk_);
  for (int j = 0; j < n_; ++j) {
    const DualQuatd expect =
        Dlb<double>(std::array<DualQuatd, 2>{g.rigid[j], rest.rigid[j]}, std::array<double, 2>{0.2, 0.8});
    EXPECT_LT(RotationAngle(out.rigid[j], expect), 1e-9);
  }
  // Nothing scheduled: the rest pose.
  Schedule empty(sk_);
  ExpectSamePose(Sampled(empty, 1.0, n_), rest, 1e-12, "empty");
}

TEST_F(Engine, NestedSchedules) {
  auto inner = std::make_shared<Schedule>(sk_);
  inner->Add({gesture_, {}, 0.5, false, "late gesture"});
  EXPECT_DOUBLE_EQ(inner->Duration(), 2.5);
  Schedule outer(sk_);
  outer.Add({inner, {}, 2.0, false, "inner"});
  EXPECT_DOUBLE_EQ(outer.Duration(), 4.5);
  // Outer t = 3.5 → inner 1.5 → gesture 1.0.
  ExpectSamePose(Sampled(outer, 3.5, n_), SampledClip(*sk_, *gesture_clip_, 1.0), 1e-12, "nested");
  // Before the inner schedule's gesture begins, the inner schedule renders the rest pose.
  ExpectSamePose(Sampled(outer, 2.2, n_), LocalPose::Rest(*sk_), 1e-12, "inner before its action");
}

TEST_F(Engine, ActionsAddedRemovedAndRetimedWhileRunning) {
  Schedule s(sk_, {}, 4);
  const int idle = s.Add({std::make_shared<Loop>(idle_), {}, 0.0, true, "idle"});
  ExpectSamePose(Sampled(s, 5.0, n_), SampledClip(*sk_, *idle_clip_, 1.0), 1e-12, "looped idle");
  const int g = s.Add({gesture_, {}, 5.5, false, "gesture"});
  EXPECT_EQ(s.FindByName("gesture"), g);
  EXPECT_EQ(s.action_count(), 2);
  // Both at full weight: the blend differs from the idle.
  EXPECT_GT(RotationAngle(Sampled(s, 6.0, n_).rigid[3], SampledClip(*sk_, *idle_clip_, 2.0).rigid[3]), 1e-3);
  EXPECT_TRUE(s.Retime(g, 10.0));
  ExpectSamePose(Sampled(s, 6.0, n_), SampledClip(*sk_, *idle_clip_, 2.0), 1e-12, "retimed away");
  EXPECT_TRUE(s.Remove(idle));
  ExpectSamePose(Sampled(s, 10.5, n_), SampledClip(*sk_, *gesture_clip_, 0.5), 1e-12, "idle removed");
  EXPECT_FALSE(s.Remove(idle));
  EXPECT_FALSE(s.Retime(idle, 1.0));
  // Full: the fifth action is refused.
  for (int i = 0; i < 3; ++i) s.Add({gesture_, {}, 20.0, false, "more"});
  EXPECT_THROW(s.Add({gesture_, {}, 0.0, false, "too many"}), Error);
  // Objects of another skeleton, curves that cannot fit, are refused.
  auto small = std::make_shared<Skeleton>(*sk_);
  small->names.pop_back();
  small->parents.pop_back();
  small->rest.pop_back();
  small->inverse_bind.pop_back();
  Schedule s2(sk_);
  EXPECT_THROW(s2.Add({std::make_shared<StaticPose>(LocalPose::Rest(*small)), {}, 0.0, false, "x"}), Error);
  BlendingParams fractions;
  fractions.curves = {Curve::CosineFade(0.2, 0.2)};
  EXPECT_THROW(s2.Add({std::make_shared<Loop>(idle_), fractions, 0.0, false, "unbounded with fractions"}), Error);
}

TEST_F(Engine, GainFadesWithACosine) {
  Schedule s(sk_);
  const int g = s.Add({std::make_shared<Loop>(gesture_), {}, 0.0, true, "gesture"});
  EXPECT_TRUE(s.FadeGain(g, 0.0, 1.0, 2.0));
  EXPECT_DOUBLE_EQ(s.Gain(g, 0.5), 1.0);
  EXPECT_NEAR(s.Gain(g, 2.0), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(s.Gain(g, 3.5), 0.0);
  // Reversed halfway: starts from where it is.
  EXPECT_TRUE(s.FadeGain(g, 1.0, 2.0, 1.0));
  EXPECT_NEAR(s.Gain(g, 2.0), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(s.Gain(g, 3.0), 1.0);
}

TEST_F(Engine, Modifiers) {
  // Stretch: the 2 s gesture over 5 s.
  TimeStretch stretch(gesture_, 5.0);
  EXPECT_DOUBLE_EQ(stretch.Duration(), 5.0);
  ExpectSamePose(Sampled(stretch, 2.5, n_), SampledClip(*sk_, *gesture_clip_, 1.0), 1e-12, "stretch");
  // Loop twice, or forever.
  Loop twice(gesture_, 2), forever(gesture_);
  EXPECT_DOUBLE_EQ(twice.Duration(), 4.0);
  EXPECT_EQ(forever.Duration(), kUnbounded);
  ExpectSamePose(Sampled(twice, 2.5, n_), SampledClip(*sk_, *gesture_clip_, 0.5), 1e-12, "loop");
  ExpectSamePose(Sampled(twice, 9.0, n_), SampledClip(*sk_, *gesture_clip_, 2.0), 1e-12, "loop end");
  ExpectSamePose(Sampled(forever, 100.25, n_), SampledClip(*sk_, *gesture_clip_, 0.25), 1e-9, "loop forever");
  // Window [0.5, 1.5).
  Window window(gesture_, 0.5, 1.5);
  EXPECT_DOUBLE_EQ(window.Duration(), 1.0);
  ExpectSamePose(Sampled(window, 0.25, n_), SampledClip(*sk_, *gesture_clip_, 0.75), 1e-12, "window");
  EXPECT_THROW(Window(gesture_, 1.0, 3.0), Error);
  EXPECT_THROW(TimeStretch(std::make_shared<Loop>(gesture_), 2.0), Error);
  // Global transform: the roots move and turn, the rest of the body follows unchanged.
  const DualQuatd shift = DualQuatd::FromRotationTranslation(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY())),
                                                             Eigen::Vector3d(1, 0, 2));
  GlobalTransform moved(gesture_, sk_, shift);
  const LocalPose m = Sampled(moved, 0.4, n_), g = SampledClip(*sk_, *gesture_clip_, 0.4);
  const DualQuatd root = shift * g.rigid[0];
  EXPECT_LT(RotationAngle(m.rigid[0], root), 1e-12);
  EXPECT_LT((m.rigid[0].Translation() - root.Translation()).norm(), 1e-12);
  for (int j = 1; j < n_; ++j) EXPECT_EQ(m.rigid[j].real().coeffs(), g.rigid[j].real().coeffs());
}

// Model-space rotations (before root_parent) of a pose.
std::vector<Eigen::Quaterniond> ModelRotations(const Skeleton& sk, const LocalPose& p) {
  std::vector<Eigen::Quaterniond> r(sk.size());
  for (int j = 0; j < sk.size(); ++j)
    r[j] = (sk.parents[j] < 0 ? Eigen::Quaterniond::Identity() : r[sk.parents[j]]) * p.rigid[j].Rotation();
  return r;
}

TEST_F(Engine, MirrorSwapsSidesAndIsAnInvolution) {
  auto rest = std::make_shared<StaticPose>(LocalPose::Rest(*sk_));
  Mirror mirrored_rest(rest, sk_);
  ExpectSamePose(Sampled(mirrored_rest, 0, n_), LocalPose::Rest(*sk_), 1e-12, "mirror of the rest pose");
  // Raise the left arm (in model space, relative to rest): the mirror raises the right arm by
  // the reflected rotation.
  LocalPose raised = LocalPose::Rest(*sk_);
  const int la = sk_->Find("LeftArm"), ra = sk_->Find("RightArm");
  const Eigen::Quaterniond lift(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.3, 1).normalized()));
  raised.rigid[la] = DualQuatd::FromRotationTranslation(raised.rigid[la].Rotation() * lift, raised.rigid[la].Translation());
  auto raised_src = std::make_shared<StaticPose>(raised);
  auto mirror = std::make_shared<Mirror>(raised_src, sk_);
  const LocalPose m = Sampled(*mirror, 0, n_);
  const auto rest_model = ModelRotations(*sk_, LocalPose::Rest(*sk_));
  const auto raised_model = ModelRotations(*sk_, raised);
  const auto m_model = ModelRotations(*sk_, m);
  // Model-space change of the left arm, reflected across x = 0, is the right arm's change.
  const Eigen::Quaterniond left_change = raised_model[la] * rest_model[la].conjugate();
  const Eigen::Quaterniond right_change = m_model[ra] * rest_model[ra].conjugate();
  const Eigen::Quaterniond reflected(left_change.w(), left_change.x(), -left_change.y(), -left_change.z());
  EXPECT_LT(right_change.angularDistance(reflected), 1e-9);
  EXPECT_LT(m_model[la].angularDistance(rest_model[la]), 1e-9);  // the left arm is back at rest
  // Bones keep their lengths.
  for (int j = 0; j < n_; ++j) EXPECT_NEAR(m.rigid[j].Translation().norm(), raised.rigid[j].Translation().norm(), 1e-12);
  // Mirror twice: the original.
  Mirror twice(mirror, sk_);
  ExpectSamePose(Sampled(twice, 0, n_), raised, 1e-9, "mirror of the mirror");
}

// The largest per-frame rotation step of any joint over a sampled stream.
double LargestStep(Blendable& b, int joints, double from, double to, double dt) {
  LocalPose prev = Sampled(b, from, joints), cur(joints);
  double worst = 0;
  for (double t = from + dt; t <= to; t += dt) {
    EXPECT_TRUE(b.Sample(t, {}, cur));
    for (int j = 0; j < joints; ++j) worst = std::max(worst, RotationAngle(prev.rigid[j], cur.rigid[j]));
    std::swap(prev, cur);
  }
  return worst;
}

TEST_F(Engine, OverlappingFadesDoNotJump) {
  // Idle underneath; two gestures whose cosine fades overlap; a linear ADSR one on the arms.
  auto idle_loop = std::make_shared<Loop>(idle_);
  BlendingParams fade;
  fade.curves = {Curve::CosineFade(0.4, 0.4)};
  BlendingParams arms = fade;
  JointMask m = JointMask::Uniform(n_, 0.0);
  m.Set(ResolveScope(*sk_, "left_arm"), 1.0);
  m.Set(ResolveScope(*sk_, "right_arm"), 1.0);
  arms.masks = {m};
  arms.curves = {Curve::Adsr(0.2, 0.2, 0.6, 0.3)};
  auto g2 = std::make_shared<ClipSource>(sk_, Wave(*sk_, 3, 3.0, 0.8));
  Schedule s(sk_);
  s.Add({idle_loop, {}, 0.0, true, "idle"});
  s.Add({gesture_, fade, 1.0, false, "g1"});
  s.Add({g2, fade, 2.2, false, "g2"});
  s.Add({gesture_, arms, 2.6, false, "arms"});
  const double dt = 1.0 / 60;
  const double blended = LargestStep(s, n_, 0.0, 6.0, dt);
  double own = 0;
  for (const BlendablePtr& b : {BlendablePtr(idle_loop), BlendablePtr(std::make_shared<Loop>(gesture_)), BlendablePtr(std::make_shared<Loop>(g2))})
    own = std::max(own, LargestStep(*b, n_, 0.0, 6.0, dt));
  std::printf("[fades] largest per-frame joint rotation step: blended %.4f rad, streams alone %.4f rad (ratio %.2f)\n",
              blended, own, blended / own);
  EXPECT_LE(blended, 2 * own);
}

}  // namespace
}  // namespace arview::anim
