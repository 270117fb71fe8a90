// Gaze (anim/gaze.h): a seeded 10-minute simulation per mode against Eyes Alive's statistics,
// and the eyes of a small head turned toward a viewer within their range.

#include "anim/animator.h"
#include "anim/blendable.h"
#include "anim/gaze.h"
#include "anim/schedule.h"
#include "tests/support/eyed_head.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

namespace arview::anim {
namespace {

constexpr double kMinutes = 10;
constexpr double kSeconds = 60 * kMinutes;

// P(A ≤ a) for the magnitude law A = −6.9·ln(P/15.7), P uniform in (0, 15], uncapped.
double MagnitudeCdf(double a) { return std::clamp((15.0 - 15.7 * std::exp(-a / 6.9)) / 15.0, 0.0, 1.0); }

// The Kolmogorov-Smirnov statistic of `sample` against `cdf`, and its p-value (Stephens'
// approximation of the Kolmogorov distribution, Numerical Recipes' probks).
std::pair<double, double> KolmogorovSmirnov(std::vector<double> sample, double (*cdf)(double, double), double cap) {
  std::sort(sample.begin(), sample.end());
  const double n = static_cast<double>(sample.size());
  double d = 0;
  for (std::size_t i = 0; i < sample.size(); ++i) {
    const double f = cdf(sample[i], cap);
    d = std::max({d, std::abs((i + 1) / n - f), std::abs(f - i / n)});
  }
  const double lambda = (std::sqrt(n) + 0.12 + 0.11 / std::sqrt(n)) * d;
  double p = 0, sign = 1;
  for (int k = 1; k <= 100; ++k, sign = -sign) p += 2 * sign * std::exp(-2.0 * k * k * lambda * lambda);
  return {d, std::clamp(p, 0.0, 1.0)};
}

// The law conditioned on staying below the mode's cap (capped draws are tested apart).
double CappedLawCdf(double a, double cap) { return MagnitudeCdf(a) / MagnitudeCdf(cap); }

struct Simulation {
  GazeLog log;
  double mutual_share = 0;     // sampled every 10 ms from the behaviour's output
  std::vector<double> measured_durations, expected_durations;  // of the first saccades, ms
};

// Runs the behaviour for ten minutes at 100 Hz, and around each of the first 150 saccades at
// 0.1 ms to time the motion of the gaze offset itself.
Simulation Simulate(GazeMode mode, std::uint64_t seed) {
  GazeOptions options;
  options.mode = mode;
  options.seed = seed;
  Simulation sim;
  GazeBehaviour behaviour(options);
  behaviour.set_log(&sim.log);
  long mutual = 0, samples = 0;
  for (double t = 0; t < kSeconds; t += 0.01, ++samples) {
    behaviour.Advance(t);
    mutual += behaviour.mutual();
  }
  sim.mutual_share = 100.0 * mutual / samples;

  GazeBehaviour timer(options);
  const int timed = std::min<int>(150, static_cast<int>(sim.log.saccades.size()));
  for (int i = 0; i < timed; ++i) {
    const SaccadeEvent& s = sim.log.saccades[i];
    // The last 0.1 ms sample still where the eyes were before, and the first from which the
    // offset holds still (a fixation lasts at least 1/30 s).
    timer.Advance(s.start - 0.002);
    const Eigen::Vector2d before = timer.offset_deg();
    double moved = -1, arrived = -1;
    Eigen::Vector2d previous = before;
    for (double t = s.start - 0.001; t < s.start + 0.3; t += 0.0001) {
      timer.Advance(t);
      const Eigen::Vector2d o = timer.offset_deg();
      if (moved < 0 && o != before) moved = t - 0.0001;
      if (moved >= 0 && o == previous && o != before) {
        arrived = t - 0.0001;
        break;
      }
      previous = o;
    }
    sim.measured_durations.push_back(1000 * (arrived - moved));
    sim.expected_durations.push_back(25 + 2.4 * s.amplitude_deg);
  }
  return sim;
}

void CheckMode(GazeMode mode, const char* name) {
  const SaccadeStatistics& stats = EyesAliveStatistics(mode);
  const Simulation sim = Simulate(mode, 1);
  std::vector<double> below_cap;
  int capped = 0, draws = 0, large = 0, large_with_blink = 0;
  std::size_t b = 0;
  for (const SaccadeEvent& s : sim.log.saccades) {
    if (s.to_mutual) continue;
    ++draws;
    if (s.magnitude_deg >= stats.max_magnitude_deg - 1e-12) ++capped;
    else below_cap.push_back(s.magnitude_deg);
    if (s.magnitude_deg >= GazeBehaviour::kBlinkShiftDeg) {
      ++large;
      while (b < sim.log.blinks.size() && sim.log.blinks[b].start < s.start) ++b;
      large_with_blink += b < sim.log.blinks.size() && sim.log.blinks[b].start == s.start;
    }
  }
  const auto [d, p] = KolmogorovSmirnov(below_cap, CappedLawCdf, stats.max_magnitude_deg);
  const double expected_capped = 1 - MagnitudeCdf(stats.max_magnitude_deg);
  const double blink_rate = sim.log.blinks.size() / kMinutes;
  const double default_rate = DefaultBlinkRate(mode);
  double worst_duration = 0;
  for (std::size_t i = 0; i < sim.measured_durations.size(); ++i)
    worst_duration = std::max(worst_duration, std::abs(sim.measured_durations[i] - sim.expected_durations[i]));
  std::printf("[gaze] %s, 10 min, seed 1: %zu saccades, %d look-aways (KS D %.4f p %.3f on %zu below the %.1f deg cap; "
              "%.1f%% capped, law %.1f%%), durations within %.3f ms of 25 + 2.4 A (%zu timed), %zu blinks = %.1f/min "
              "(mode %.0f), %d of %d look-aways >= %.0f deg with a blink, mutual gaze %.1f%% of the time (mode %.0f%%)\n",
              name, sim.log.saccades.size(), draws, d, p, below_cap.size(), stats.max_magnitude_deg, 100.0 * capped / draws,
              100 * expected_capped, worst_duration, sim.measured_durations.size(), sim.log.blinks.size(), blink_rate,
              default_rate, large_with_blink, large, GazeBehaviour::kBlinkShiftDeg, sim.mutual_share, stats.mutual_percent);
  EXPECT_GT(p, 0.05) << name;
  EXPECT_NEAR(static_cast<double>(capped) / draws, expected_capped, 0.05) << name;
  EXPECT_LE(worst_duration, 1.0) << name;
  EXPECT_EQ(sim.measured_durations.size(), 150u) << name;
  EXPECT_NEAR(blink_rate, default_rate, 0.1 * default_rate) << name;
  EXPECT_NEAR(sim.mutual_share, stats.mutual_percent, 5.0) << name;
  EXPECT_GT(large_with_blink, large / 2) << name << ": most large gaze shifts come with a blink";
}

TEST(GazeBehaviour, TalkingFollowsEyesAlive) { CheckMode(GazeMode::kTalking, "talking"); }
TEST(GazeBehaviour, ListeningFollowsEyesAlive) { CheckMode(GazeMode::kListening, "listening"); }

// Over 20 seeds the ten-minute shares and rates centre on the mode's (no bias; one seed's
// spread is printed for docs/anim.md).
TEST(GazeBehaviour, TwentySeedsCentreOnTheModesShareAndRate) {
  for (GazeMode mode : {GazeMode::kTalking, GazeMode::kListening}) {
    const SaccadeStatistics& stats = EyesAliveStatistics(mode);
    double share_sum = 0, share_lo = 100, share_hi = 0, rate_sum = 0, rate_lo = 1e9, rate_hi = 0;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      GazeOptions options;
      options.mode = mode;
      options.seed = seed;
      GazeBehaviour behaviour(options);
      long mutual = 0, samples = 0;
      for (double t = 0; t < kSeconds; t += 0.01, ++samples) {
        behaviour.Advance(t);
        mutual += behaviour.mutual();
      }
      const double share = 100.0 * mutual / samples, rate = behaviour.blinks_started() / kMinutes;
      share_sum += share;
      rate_sum += rate;
      share_lo = std::min(share_lo, share);
      share_hi = std::max(share_hi, share);
      rate_lo = std::min(rate_lo, rate);
      rate_hi = std::max(rate_hi, rate);
    }
    std::printf("[gaze] %s, 20 seeds x 10 min: mutual gaze %.1f%% mean (%.1f..%.1f, mode %.0f%%), blinks %.2f/min mean "
                "(%.1f..%.1f, mode %.0f)\n",
                mode == GazeMode::kTalking ? "talking" : "listening", share_sum / 20, share_lo, share_hi, stats.mutual_percent,
                rate_sum / 20, rate_lo, rate_hi, DefaultBlinkRate(mode));
    EXPECT_NEAR(share_sum / 20, stats.mutual_percent, 2.0);
    EXPECT_NEAR(rate_sum / 20, DefaultBlinkRate(mode), 0.03 * DefaultBlinkRate(mode));
  }
}

TEST(GazeBehaviour, RestBlinksSeventeenTimesAMinute) {
  GazeOptions options;
  options.mode = GazeMode::kRest;
  GazeLog log;
  GazeBehaviour behaviour(options);
  behaviour.set_log(&log);
  behaviour.Advance(kSeconds);
  std::printf("[gaze] rest, 10 min, seed 1: %zu blinks = %.1f/min (mode 17)\n", log.blinks.size(), log.blinks.size() / kMinutes);
  EXPECT_NEAR(log.blinks.size() / kMinutes, 17.0, 1.7);
  EXPECT_EQ(behaviour.blinks_started(), static_cast<long>(log.blinks.size()));
}

TEST(GazeBehaviour, AScenesBlinkRateIsKept) {
  GazeOptions options;
  options.blink_rate_per_min = 10;
  GazeBehaviour behaviour(options);
  behaviour.Advance(kSeconds);
  EXPECT_NEAR(behaviour.blinks_started() / kMinutes, 10.0, 1.0);
}

TEST(GazeBehaviour, SeededAndReproducibleWhenSampledBackwards) {
  GazeOptions options;
  options.mode = GazeMode::kTalking;
  options.seed = 7;
  GazeBehaviour a(options), b(options);
  for (int frame = 0; frame <= 1800; ++frame) a.Advance(frame / 60.0);  // 30 s at 60 Hz
  b.Advance(50);
  b.Advance(30);  // back in time: restarts from the seed
  EXPECT_LT((a.offset_deg() - b.offset_deg()).norm(), 1e-12);
  EXPECT_EQ(a.blinks_started(), b.blinks_started());
  options.seed = 8;
  GazeLog seven, eight;
  GazeBehaviour c(options);
  c.set_log(&eight);
  b.set_log(&seven);
  b.Advance(0);
  b.Advance(30);
  c.Advance(30);
  ASSERT_FALSE(seven.saccades.empty());
  ASSERT_FALSE(eight.saccades.empty());
  EXPECT_NE(seven.saccades.front().start, eight.saccades.front().start);
}

// A render at a far time does not walk every event since 0: it starts there, on the viewer.
TEST(GazeBehaviour, AFarJumpStartsAfreshAtTheNewTime) {
  GazeOptions options;
  GazeBehaviour far(options), near(options);
  far.Advance(1e12);
  near.Advance(0);
  EXPECT_TRUE(far.mutual());
  EXPECT_EQ(far.offset_deg(), near.offset_deg());
  far.Advance(1e12 + 30);
  near.Advance(30);
  EXPECT_EQ(far.blinks_started(), near.blinks_started());
}

TEST(GazeBehaviour, BlinkShutsInFiftyMillisecondsAndOpensByTwoHundredFifty) {
  EXPECT_EQ(BlinkClosure(-0.01), 0);
  EXPECT_NEAR(BlinkClosure(0.05), 1, 1e-12);
  EXPECT_GT(BlinkClosure(0.025), 0.2);
  EXPECT_GT(BlinkClosure(0.15), 0.2);
  EXPECT_EQ(BlinkClosure(0.25), 0);
  EXPECT_EQ(BlinkClosure(0.3), 0);
}

TEST(GazeOptions, BadValuesAreRefusedNamingThem) {
  GazeOptions o;
  o.blink_rate_per_min = -1;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.range.up_deg = 0;
  try {
    o.Check();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("eye range"), std::string::npos) << e.what();
  }
}

Skeleton SmallHead() { return testing::EyedHead(); }

Eigen::Vector3d EyeForward(const Skeleton& sk, const LocalPose& pose, int eye) {
  std::vector<Eigen::Matrix4d> model(sk.size());
  MustRun(LocalToModelJob{&sk, &pose, model}, "test");
  return model[eye].block<3, 3>(0, 0) * Eigen::Vector3d::UnitZ();
}

TEST(EyeGaze, EyesPointAtAViewerWithinRangeAndStopAtTheRange) {
  const Skeleton sk = SmallHead();
  const GazeRig rig = FindGazeRig(sk);
  ASSERT_TRUE(rig.valid());
  EXPECT_EQ(rig.eyes[0].upper_lid, sk.Find("LeftUpperLid"));
  GazeOptions options;
  Gaze gaze(sk, rig, options);
  std::vector<Eigen::Matrix4d> model(sk.size());
  LocalPose pose = LocalPose::Rest(sk);
  MustRun(LocalToModelJob{&sk, &pose, model}, "test");
  // At t = 0 the behaviour fixates the viewer (a mutual fixation first).
  const Eigen::Vector3d viewer(0.4, 1.8, 0.8);
  gaze.Apply(0.0, viewer, model, pose);
  ASSERT_TRUE(gaze.frame().eyes_on_viewer);
  for (int s = 0; s < 2; ++s) {
    const int eye = rig.eyes[s].eye;
    const Eigen::Vector3d centre = model[0].block<3, 3>(0, 0) * sk.rest[eye].translation + model[0].block<3, 1>(0, 3);
    const Eigen::Vector3d want = (viewer - centre).normalized();
    const Eigen::Vector3d got = EyeForward(sk, pose, eye);
    EXPECT_LT(std::acos(std::min(1.0, want.dot(got))) * 180 / M_PI, 1e-6);
  }
  // A viewer 60° to the side: the eyes stop at 35° and the viewer is not met.
  const Eigen::Vector3d aside(std::sin(60 * M_PI / 180), 1.63, std::cos(60 * M_PI / 180));
  gaze.Apply(0.01, aside, model, pose);
  EXPECT_FALSE(gaze.frame().eyes_on_viewer);
  const Eigen::Vector3d f = EyeForward(sk, pose, rig.eyes[0].eye);
  EXPECT_NEAR(std::atan2(f.x(), f.z()) * 180 / M_PI, 35.0, 1e-6);
  // Unknown viewer: ahead.
  gaze.Apply(0.02, Eigen::Vector3d::Constant(NAN), model, pose);
  EXPECT_FALSE(gaze.frame().eyes_on_viewer);
  EXPECT_GT(EyeForward(sk, pose, rig.eyes[0].eye).z(), std::cos(1e-6));
}

TEST(EyeGaze, LidsCloseOnABlinkAndTheUpperLidFollowsThePitch) {
  const Skeleton sk = SmallHead();
  const GazeRig rig = FindGazeRig(sk);
  GazeOptions options;
  Gaze gaze(sk, rig, options);
  GazeLog log;
  gaze.behaviour().set_log(&log);
  std::vector<Eigen::Matrix4d> model(sk.size());
  LocalPose pose = LocalPose::Rest(sk);
  MustRun(LocalToModelJob{&sk, &pose, model}, "test");
  const Eigen::Vector3d below(0, 1.0, 1.0);  // 30° down from the eyes: the eyes stop at 25° down
  gaze.Apply(0.0, below, model, pose);
  auto lid_pitch = [&](int joint) {
    const Eigen::Vector3d f = pose.rigid[joint].Rotation() * Eigen::Vector3d::UnitZ();
    return std::asin(f.y()) * 180 / M_PI;
  };
  EXPECT_NEAR(lid_pitch(rig.eyes[0].upper_lid), -25, 1e-6);
  gaze.Apply(120.0, below, model, pose);
  ASSERT_FALSE(log.blinks.empty());
  const double shut = log.blinks.front().start + 0.05;
  gaze.Apply(shut, below, model, pose);
  EXPECT_TRUE(gaze.frame().blinking);
  EXPECT_NEAR(lid_pitch(rig.eyes[0].upper_lid), -45, 1e-6);
  EXPECT_NEAR(lid_pitch(rig.eyes[0].lower_lid), 8, 1e-6);
  gaze.Apply(shut + 0.21, below, model, pose);
  EXPECT_FALSE(gaze.frame().blinking);
}

TEST(EyeGaze, ASkeletonWithoutEyesHasNoRig) {
  Skeleton sk = SmallHead();
  sk.names[1] = "LeftEyeball";
  EXPECT_FALSE(FindGazeRig(sk).valid());
  EXPECT_THROW(Gaze(sk, FindGazeRig(sk), GazeOptions{}), Error);
}

// A body whose eyes hang below a chain with a branch beside it (an arm) and joints after the
// eyes (a jaw, a highlight on the left eye), under a scaled, turned root_parent.
Skeleton EyedBody() {
  Skeleton sk;
  sk.names = {"Hips", "Spine", "LeftArm", "Neck", "LeftHand", "Head", "LeftEye", "LeftUpperLid",
              "LeftLowerLid", "RightEye", "RightUpperLid", "RightLowerLid", "Jaw", "LeftEyeHighlight"};
  sk.parents = {-1, 0, 1, 1, 2, 3, 5, 5, 5, 5, 5, 5, 5, 6};
  sk.rest.resize(sk.names.size());
  const double up[] = {1.0, 0.2, 0.15, 0.25, 0.3, 0.1};
  for (int j = 0; j < 6; ++j) sk.rest[j].translation = {j == 2 || j == 4 ? 0.2 : 0.0, up[j], 0};
  for (int j = 6; j < 12; ++j) sk.rest[j].translation = {j < 9 ? 0.03 : -0.03, 0.03, 0.09};
  sk.rest[12].translation = {0, -0.05, 0.05};
  sk.rest[13].translation = {0, 0, 0.012};
  sk.inverse_bind.assign(sk.names.size(), Eigen::Matrix4d::Identity());
  sk.root_parent.block<3, 3>(0, 0) = 0.9 * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  sk.root_parent.block<3, 1>(0, 3) = Eigen::Vector3d(0.5, 0, -1);
  return sk;
}

// Every joint turned at 30 keys/s for 4 s, the hips moving and the head's scale changing.
std::shared_ptr<Clip> Fidget(const Skeleton& sk) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  auto clip = std::make_shared<Clip>();
  clip->name = "fidget";
  clip->duration = 4;
  clip->tracks.resize(sk.size());
  for (int i = 0; i <= 120; ++i) {
    const double t = i / 30.0;
    for (int j = 0; j < sk.size(); ++j) {
      const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      clip->tracks[j].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * u(rng), axis))});
    }
    clip->tracks[0].translation.push_back({t, Eigen::Vector3d(0.05 * u(rng), 1.0, 0.05 * u(rng))});
    clip->tracks[5].scale.push_back({t, Eigen::Vector3d::Constant(1.0 + 0.05 * u(rng))});
  }
  return clip;
}

TEST(LocalToModel, AJointChainGivesTheMatricesOfAFullPassBitForBit) {
  const Skeleton sk = EyedBody();
  const int head = sk.Find("Head");
  const std::vector<int> chain = JointChain(sk, std::vector<int>{head, head});
  EXPECT_EQ(chain, (std::vector<int>{0, 1, 3, 5}));
  LocalPose pose(sk.size());
  MustRun(SamplingJob{&sk, Fidget(sk).get(), 1.37, true, &pose}, "test");
  std::vector<Eigen::Matrix4d> full(sk.size()), part(sk.size(), Eigen::Matrix4d::Constant(7.0));
  MustRun(LocalToModelJob{&sk, &pose, full}, "test");
  MustRun(JointsToModelJob{&sk, &pose, chain, part}, "test");
  for (int j = 0; j < sk.size(); ++j) {
    const bool listed = std::find(chain.begin(), chain.end(), j) != chain.end();
    if (listed) EXPECT_TRUE(part[j] == full[j]) << sk.names[j];
    else EXPECT_TRUE(part[j] == Eigen::Matrix4d::Constant(7.0)) << sk.names[j] << " was written";
  }
  // Out of order, repeated or out of range: refused, nothing written.
  for (const std::vector<int>& bad : {std::vector<int>{3, 1}, std::vector<int>{1, 1}, std::vector<int>{-1}, std::vector<int>{14}}) {
    std::vector<Eigen::Matrix4d> untouched(sk.size(), Eigen::Matrix4d::Zero());
    EXPECT_FALSE((JointsToModelJob{&sk, &pose, bad, untouched}.Run()));
    EXPECT_TRUE(untouched[0].isZero(0));
  }
  EXPECT_THROW(JointChain(sk, std::vector<int>{14}), Error);
}

// The Animator computes only the chain to the eyes' parents before gaze, then every joint once:
// its frames equal, bit for bit, a full local-to-model pass before gaze and another after it.
TEST(EyeGaze, TheAnimatorsFramesEqualFullPassesBeforeAndAfterGaze) {
  const auto sk = std::make_shared<const Skeleton>(EyedBody());
  const std::shared_ptr<Clip> clip = Fidget(*sk);
  auto schedule = [&] {
    auto s = std::make_shared<Schedule>(sk);
    s->Add({std::make_shared<ClipSource>(sk, clip), {}, 0, true, "fidget"});
    return s;
  };
  AnimatorOptions options;
  options.view_action.clear();
  options.gaze = GazeSetup{FindGazeRig(*sk), GazeOptions{}};
  options.gaze->options.mode = GazeMode::kTalking;
  Animator animator(sk, schedule(), options);
  const std::shared_ptr<Schedule> reference_schedule = schedule();
  Gaze reference_gaze(*sk, options.gaze->rig, options.gaze->options);
  LocalPose local = LocalPose::Rest(*sk);
  std::vector<Eigen::Matrix4d> model(sk->size());
  std::vector<Eigen::Matrix4f> skin(sk->size());
  std::vector<DualQuatf> skin_dq(sk->size());
  int differing = 0, moved_eyes = 0;
  for (int frame = 0; frame < 600; ++frame) {
    const double t = frame / 60.0;
    FrameInputs in;
    in.viewer = Eigen::Vector3d(0.8 * std::sin(t), 1.8, 1.5);
    const AnimatorFrame& f = animator.Update(t, in);
    ASSERT_TRUE(reference_schedule->Sample(t, in, local));
    const Eigen::Quaterniond eye_as_clipped = local.rigid[6].Rotation();
    MustRun(LocalToModelJob{sk.get(), &local, model}, "test");
    reference_gaze.Apply(t, in.viewer, model, local);
    MustRun(LocalToModelJob{sk.get(), &local, model}, "test");
    MustRun(SkinningMatricesJob{sk.get(), model, skin, skin_dq}, "test");
    for (int j = 0; j < sk->size(); ++j) {
      differing += !(f.model[j] == model[j]) || !(f.skinning_matrices[j] == skin[j]) ||
                   f.skinning_dual_quats[j].real().coeffs() != skin_dq[j].real().coeffs() ||
                   f.skinning_dual_quats[j].dual().coeffs() != skin_dq[j].dual().coeffs();
    }
    moved_eyes += f.local[0].rigid[6].Rotation().angularDistance(eye_as_clipped) > 1e-3;
    EXPECT_EQ(f.gaze.eyes_on_viewer, reference_gaze.frame().eyes_on_viewer);
  }
  EXPECT_EQ(differing, 0) << "joint matrices in 600 frames unlike the two full passes'";
  EXPECT_GT(moved_eyes, 500) << "gaze turned the eyes";
}

}  // namespace
}  // namespace arview::anim
