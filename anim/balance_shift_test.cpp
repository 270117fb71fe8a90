// The balance-shift runtime on hand-made models whose answers are known: the segment chosen by
// the eigenvalue-weighted distance, the fitting by offsets at the ends, the model's checks.
// (Learning from a constructed recording and the walk: anim_authoring/balance_test.cpp.)

#include "anim/balance_shift.h"

#include <gtest/gtest.h>

namespace arview::anim {
namespace {

// One joint (3 values) and the root's translation (3): 6 values; the components are the first
// two axes, with eigenvalues 4 and 1 (the first varies twice as much as the second).
BalanceModel TwoComponentModel() {
  BalanceModel m;
  m.joints = {0};
  m.root = 0;
  m.mean = Eigen::VectorXd::Zero(6);
  m.components = Eigen::MatrixXd::Zero(6, 2);
  m.components(0, 0) = m.components(1, 1) = 1;
  m.eigenvalues = Eigen::Vector2d(4, 1);
  return m;
}

Eigen::VectorXd Posture(double a, double b, double c = 0) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(6);
  p << a, b, c, 0, 0, 0;
  return p;
}

BalanceModel::Segment Segment(Support from, Support to, std::vector<Eigen::VectorXd> frames) {
  BalanceModel::Segment s;
  s.from = from;
  s.to = to;
  s.frames = std::move(frames);
  return s;
}

TEST(BalanceShift, DistanceIsEigenvalueWeighted) {
  const BalanceModel m = TwoComponentModel();
  EXPECT_DOUBLE_EQ(m.Distance(Posture(1, 0), Posture(0, 0)), 2.0);  // sqrt(4 · 1²)
  EXPECT_DOUBLE_EQ(m.Distance(Posture(0, 1.5), Posture(0, 0)), 1.5);  // sqrt(1 · 1.5²)
  EXPECT_DOUBLE_EQ(m.Distance(Posture(0, 0, 9), Posture(0, 0)), 0.0);  // beyond the kept components
}

TEST(BalanceShift, ChoosesTheSegmentNearestByTheEigenvalueWeightedDistance) {
  BalanceModel m = TwoComponentModel();
  const Eigen::VectorXd p = Posture(0, 0), q = Posture(0.5, 0.5);
  // Both end at q. Candidate 0 starts 1 away from p along PC 1 (distance 2), candidate 1 starts
  // 1.5 away along PC 2 (distance 1.5): unweighted, 0 would be the nearer; weighted, 1 is.
  m.segments.push_back(Segment(Support::kLeft, Support::kRight, {Posture(1, 0), q}));
  m.segments.push_back(Segment(Support::kLeft, Support::kRight, {Posture(0, 1.5), q}));
  // A nearer segment between other categories is not a candidate.
  m.segments.push_back(Segment(Support::kLeft, Support::kBoth, {p, q}));
  EXPECT_EQ(ChooseSegment(m, Support::kLeft, Support::kRight, p, q), 1);
  // The end counts as much as the start (the thesis's max of both): q moved onto candidate 0's
  // end and away from candidate 1's (distance sqrt(4 · 1.1² + 0.5²) = 2.26 > 2) turns the choice.
  m.segments[0].frames.back() = Posture(1.6, 0);
  EXPECT_EQ(ChooseSegment(m, Support::kLeft, Support::kRight, p, Posture(1.6, 0)), 0);
  EXPECT_EQ(ChooseSegment(m, Support::kRight, Support::kLeft, p, q), -1);  // none recorded
}

TEST(BalanceShift, FittingInterpolatesTheEndOffsets) {
  // A recorded segment of three frames; fitted to start at p and end at q.
  const BalanceModel::Segment a = Segment(Support::kLeft, Support::kRight, {Posture(0, 0), Posture(1, 2), Posture(2, 0)});
  const Eigen::VectorXd p = Posture(0.5, 0, 0.1), q = Posture(1, 1, -0.1);
  Eigen::VectorXd out;
  FittedPosture(a, p, q, 0.0, out);
  EXPECT_EQ(out, p);
  FittedPosture(a, p, q, 1.0, out);
  EXPECT_LT((out - q).cwiseAbs().maxCoeff(), 1e-15);
  // Half way: the middle frame plus half of each end's offset, (p − a_0) and (q − a_e).
  FittedPosture(a, p, q, 0.5, out);
  const Eigen::VectorXd expect = Posture(1, 2) + 0.5 * (p - Posture(0, 0)) + 0.5 * (q - Posture(2, 0));
  EXPECT_LT((out - expect).cwiseAbs().maxCoeff(), 1e-15);
  // A quarter: between frames 0 and 1, offsets three quarters p's, one quarter q's.
  FittedPosture(a, p, q, 0.25, out);
  const Eigen::VectorXd quarter = Posture(0.5, 1) + 0.75 * (p - Posture(0, 0)) + 0.25 * (q - Posture(2, 0));
  EXPECT_LT((out - quarter).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(BalanceShift, ModelCheckRefusesAGraphThatCannotGoOn) {
  BalanceModel m = TwoComponentModel();
  m.segments.push_back(Segment(Support::kLeft, Support::kRight, {Posture(0, 0), Posture(1, 0)}));
  m.counts[0][2] = 1;
  m.rests[0] = {Posture(0, 0)};
  m.rests[2] = {Posture(1, 0)};
  m.dwell_min[0] = m.dwell_max[0] = 1;
  EXPECT_THROW(m.Check(1), Error);  // the right cannot be left
  m.segments.push_back(Segment(Support::kRight, Support::kLeft, {Posture(1, 0), Posture(0, 0)}));
  m.counts[2][0] = 1;
  m.dwell_min[2] = 0.5;
  m.dwell_max[2] = 2;
  EXPECT_NO_THROW(m.Check(1));
  m.segments.back().frames.pop_back();
  EXPECT_THROW(m.Check(1), Error);  // a segment of one frame
}

// Left and right, each resting 1–5 s (so the random part of a pause is up to 4 s), a 0.5 s shift
// between them: the walk's rests as the activation's pause scale (FrameInputs) sets them.
BalanceModel LeftRightModel() {
  BalanceModel m = TwoComponentModel();
  std::vector<Eigen::VectorXd> left_to_right, right_to_left;
  for (int k = 0; k <= 15; ++k) {
    left_to_right.push_back(Posture(k / 15.0, 0));
    right_to_left.push_back(Posture(1 - k / 15.0, 0));
  }
  m.segments = {Segment(Support::kLeft, Support::kRight, left_to_right), Segment(Support::kRight, Support::kLeft, right_to_left)};
  m.counts[0][2] = m.counts[2][0] = 1;
  m.rests[0] = {Posture(0, 0)};
  m.rests[2] = {Posture(1, 0)};
  m.dwell_min[0] = m.dwell_min[2] = 1;
  m.dwell_max[0] = m.dwell_max[2] = 5;
  return m;
}

// The rests that began and ended within `seconds` of a walk sampled at 30 Hz under `scale`.
std::vector<double> RestsUnder(double scale, std::uint64_t seed, double seconds) {
  auto sk = std::make_shared<Skeleton>();
  sk->names = {"root"};
  sk->parents = {-1};
  sk->rest = {Transform{}};
  sk->inverse_bind = {Eigen::Matrix4d::Identity()};
  BalanceShifter walk(sk, std::make_shared<const BalanceModel>(LeftRightModel()), seed);
  FrameInputs inputs;
  inputs.pause_offset_scale = scale;
  LocalPose pose = LocalPose::Rest(*sk);
  std::vector<double> rests;
  double rest_began = -1;
  for (int frame = 0; frame < seconds * 30; ++frame) {
    EXPECT_TRUE(walk.Sample(frame / 30.0, inputs, pose));
    const BalanceShifter::State& s = walk.state();
    if (s.segment < 0 && s.t0 > 0 && s.t0 != rest_began) {
      rest_began = s.t0;
      rests.push_back(s.t1 - s.t0);
    }
  }
  return rests;
}

double Mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0 : sum / static_cast<double>(v.size());
}

TEST(BalanceShift, HigherActivationGivesShorterPausesInASeededWalk) {
  // The thesis's Eq. 4.2 with α = β = 1: activation 0.9 scales the pauses' random part by 0.1,
  // activation −0.5 by 1.5 (dialogue::PauseOffsetScale); the same seed makes the same draws.
  const std::vector<double> excited = RestsUnder(0.1, 17, 120), calm = RestsUnder(1.5, 17, 120);
  const std::vector<double> neutral = RestsUnder(1.0, 17, 120);
  ASSERT_GE(calm.size(), 10u);
  EXPECT_GT(excited.size(), calm.size());  // shorter pauses, more shifts
  for (double r : excited) EXPECT_LE(r, 1 + 0.1 * 4 + 1e-9);  // p_m + 0.1·p_o at most
  for (double r : calm) EXPECT_GE(r, 1 - 1e-9);               // never below the recorded minimum
  EXPECT_GT(Mean(calm), Mean(neutral));
  EXPECT_GT(Mean(neutral), Mean(excited));
  // The default (no emotion) is the data's own pauses: within the recorded range.
  for (double r : neutral) {
    EXPECT_GE(r, 1 - 1e-9);
    EXPECT_LE(r, 5 + 1e-9);
  }
}

}  // namespace
}  // namespace arview::anim
