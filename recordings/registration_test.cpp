#include "recordings/registration.h"

#include <cmath>

#include <gtest/gtest.h>

namespace arview::recordings {
namespace {

constexpr double kF = 500;
constexpr double kFps = 30;

calib::Camera TestCamera() { return calib::Camera::Pinhole(640, 480, kF, kF, 320, 240); }

// A camera at `centre` looking along +y (world), its x along world +x and its y down (world −z).
calib::Pose LookingAlongY(const Eigen::Vector3d& centre) {
  Eigen::Matrix3d R_wc;
  R_wc << Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY();
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(R_wc), centre);
}

// A walk sideways along x at 0.3 m/s with a little height, then (for `still_frames`) a tripod.
Trajectory WalkThenStill(int moving_frames, int still_frames) {
  Trajectory out;
  for (int i = 0; i < moving_frames + still_frames; ++i) {
    const int k = std::min(i, moving_frames);
    const Eigen::Vector3d centre(0.01 * k, 0, 0.1 * std::sin(0.05 * k));
    out.push_back({i / kFps, LookingAlongY(centre)});
  }
  return out;
}

AccuracyReport Unaligned(const Trajectory& estimate, const Trajectory& groundtruth) {
  AccuracyOptions o;
  o.align = AlignMode::kNone;
  return EvaluateTrajectory(estimate, groundtruth, o);
}

TEST(Registration, AnExactEstimateHasNoErrorAndFullRecall) {
  const Trajectory truth = WalkThenStill(90, 0);
  RegistrationOptions o;
  o.points = {{0, 2, 0}, {0.3, 2.2, 0.5}};
  const RegistrationReport r = EvaluateRegistration(Unaligned(truth, truth), truth, truth, TestCamera(), o);
  EXPECT_EQ(r.frames, 90);
  EXPECT_LT(r.frame_max_px.max, 1e-9);
  EXPECT_EQ(r.share_over, 0);
  ASSERT_EQ(r.recall.size(), 3u);
  for (const RecallAt& k : r.recall) EXPECT_DOUBLE_EQ(k.recall, 1.0);
}

TEST(Registration, AnEstimateOffByOneCentimetreSidewaysIsOffByFOverDistanceInPixels) {
  const Trajectory truth = WalkThenStill(60, 0);
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) p.pose = LookingAlongY(p.pose.Center() + Eigen::Vector3d(0.01, 0, 0));
  RegistrationOptions o;
  o.points = {{0.2, 2, 0}};  // 2 m in front of the first camera
  const RegistrationReport r = EvaluateRegistration(Unaligned(estimate, truth), estimate, truth, TestCamera(), o);
  // Depth along y stays 2 m whatever x is: f · 0.01 / 2 = 2.5 px on every frame.
  EXPECT_NEAR(r.frame_mean_px.median, 2.5, 1e-9);
  EXPECT_NEAR(r.frame_max_px.max, 2.5, 1e-9);
  EXPECT_EQ(r.share_over, 0);
  o.over_px = 2;
  EXPECT_DOUBLE_EQ(EvaluateRegistration(Unaligned(estimate, truth), estimate, truth, TestCamera(), o).share_over, 1.0);
  // 1 cm off, no turn: within 2 cm/2° and 5 cm/5°.
  EXPECT_DOUBLE_EQ(r.recall[1].recall, 1.0);
  EXPECT_DOUBLE_EQ(r.recall[2].recall, 1.0);
}

TEST(Registration, TheTrueGeometryIsScoredOnThePointsEachTrueViewSees) {
  const Trajectory truth = WalkThenStill(30, 0);
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) p.pose = LookingAlongY(p.pose.Center() + Eigen::Vector3d(0.01, 0, 0));
  Sim3 map_to_world;  // the estimate's world is the truth's moved: the ground-truth points are not
  map_to_world.t = {5, 0, 0};
  Trajectory in_map = estimate, truth_in_map = truth;
  for (StampedPose& p : in_map) p.pose = Transform(map_to_world.Inverse(), p.pose);
  for (StampedPose& p : truth_in_map) p.pose = Transform(map_to_world.Inverse(), p.pose);
  AccuracyOptions o;
  o.align_with = &truth_in_map;
  RegistrationOptions reg;
  // 2 m ahead in view (2.5 px off), 1 m ahead far outside the image (left out), behind (left out).
  reg.groundtruth_points = {{0.2, 2, 0}, {-4, 1, 0}, {0, -2, 0}};
  const RegistrationReport r = EvaluateRegistration(EvaluateTrajectory(in_map, truth, o), in_map, truth, TestCamera(), reg);
  EXPECT_EQ(r.geometry_frames, 30);
  EXPECT_NEAR(r.geometry_mean_px.max, 2.5, 1e-6);
  EXPECT_NEAR(r.geometry_mean_px.median, 2.5, 1e-6);
  EXPECT_EQ(r.frames, 0);  // no scene points
}

TEST(Registration, TheErrorIsTheSameAfterASimilarityOfTheEstimatesWorld) {
  const Trajectory truth = WalkThenStill(60, 0);
  Trajectory estimate = truth;
  for (StampedPose& p : estimate) p.pose = LookingAlongY(p.pose.Center() + Eigen::Vector3d(0, 0, 0.004));
  Sim3 map_to_world;  // the map's world: another scale, turned and moved
  map_to_world.scale = 2;
  map_to_world.R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  map_to_world.t = {1, -2, 0.5};
  const Sim3 world_to_map = map_to_world.Inverse();
  Trajectory in_map = estimate;
  for (StampedPose& p : in_map) p.pose = Transform(world_to_map, p.pose);
  AccuracyOptions sim3;
  Trajectory truth_in_map = truth;
  for (StampedPose& p : truth_in_map) p.pose = Transform(world_to_map, p.pose);
  sim3.align_with = &truth_in_map;  // the exact alignment, as a map's keyframes would give
  RegistrationOptions o;
  o.points = {world_to_map(Eigen::Vector3d(0.2, 2, 0))};
  const RegistrationReport r =
      EvaluateRegistration(EvaluateTrajectory(in_map, truth, sim3), in_map, truth, TestCamera(), o);
  EXPECT_NEAR(r.frame_mean_px.median, kF * 0.004 / 2, 1e-6);
}

TEST(Registration, JitterOnAStillCameraIsTheAnchorsShiverAfterItsTrend) {
  const Trajectory truth = WalkThenStill(60, 90);
  Trajectory estimate = truth;
  // On the tripod the estimate shivers ±1 mm sideways and drifts 1 mm a second: the drift is
  // the trend, the shiver the jitter.
  for (size_t i = 60; i < estimate.size(); ++i) {
    const double shiver = (i % 2 == 0 ? 1 : -1) * 0.001;
    const double drift = 0.001 * (estimate[i].timestamp - estimate[60].timestamp);
    estimate[i].pose = LookingAlongY(truth[i].pose.Center() + Eigen::Vector3d(shiver + drift, 0, 0));
  }
  RegistrationOptions o;
  const Eigen::Vector3d anchor = truth.back().pose.Center() + Eigen::Vector3d(0, 2, 0);
  o.points = {anchor};
  const RegistrationReport r = EvaluateRegistration(Unaligned(estimate, truth), estimate, truth, TestCamera(), o);
  ASSERT_EQ(r.stills.size(), 1u);
  const StillSegment& s = r.stills[0];
  EXPECT_EQ(s.frames, 90);
  EXPECT_NEAR(s.anchor_distance, 2.0, 1e-9);
  // ±1 mm at 2 m: ±0.25 px; a 31-frame window's mean of an alternating sign leaves 1/31 of it.
  EXPECT_NEAR(s.jitter_px, 0.25, 0.25 / 31 + 1e-6);
  EXPECT_NEAR(s.jitter_arcmin, s.jitter_px / kF * 180 / M_PI * 60, 1e-9);
  EXPECT_NEAR(s.jitter_mm, 1.0, 1.0 / 31 + 1e-6);  // the shiver itself
  EXPECT_FALSE(s.smoothed_jitter_px);
  // The moving frames are exact: their fast error is zero.
  ASSERT_TRUE(r.fast_error_px);
  EXPECT_LT(*r.fast_error_px, 1e-9);

  // A smoothed centre that stays put (stamped as stats.json prints times, a little off the
  // trajectory file's) takes the shiver out.
  std::vector<StampedCentre> smoothed;
  for (const StampedPose& p : truth) smoothed.push_back({p.timestamp + 2e-7, p.pose.Center()});
  o.smoothed = &smoothed;
  const RegistrationReport with = EvaluateRegistration(Unaligned(estimate, truth), estimate, truth, TestCamera(), o);
  ASSERT_TRUE(with.stills.at(0).smoothed_jitter_px);
  EXPECT_LT(*with.stills[0].smoothed_jitter_px, 1e-9);
  EXPECT_DOUBLE_EQ(with.stills[0].jitter_px, s.jitter_px);
}

TEST(Registration, NoStillSegmentShorterThanTheMinimum) {
  const Trajectory truth = WalkThenStill(60, 20);  // 0.67 s on the tripod
  RegistrationOptions o;
  o.points = {{0.5, 2, 0}};
  EXPECT_TRUE(EvaluateRegistration(Unaligned(truth, truth), truth, truth, TestCamera(), o).stills.empty());
}

TEST(Registration, RemoveTrendLeavesNothingOfALineAndKeepsOnlyWholeWindows) {
  std::vector<double> times;
  std::vector<Eigen::Vector2d> values;
  for (int i = 0; i < 100; ++i) {
    times.push_back(i / kFps);
    values.emplace_back(3 + 2 * times.back(), -1 * times.back());
  }
  const std::vector<Eigen::Vector2d> rest = RemoveTrend(times, values, 1.0);
  EXPECT_EQ(rest.size(), 100u - 30u);  // 15 at each end lack a whole window
  for (const Eigen::Vector2d& v : rest) EXPECT_LT(v.norm(), 1e-9);
}

TEST(Registration, TheSmoothingsLagIsTheShiftBetweenRawAndSmoothedCentres) {
  const Trajectory truth = WalkThenStill(150, 0);
  Trajectory estimate;
  std::vector<StampedCentre> smoothed;
  for (int i = 0; i < 150; ++i) {
    const double t = i / kFps;
    auto at = [](double s) { return Eigen::Vector3d(std::sin(2 * s), 0.5 * std::cos(3 * s), 0.1 * s); };
    estimate.push_back({t, LookingAlongY(at(t))});
    smoothed.push_back({t, at(t - 2 / kFps)});  // two frames behind
  }
  RegistrationOptions o;
  o.smoothed = &smoothed;
  const RegistrationReport r = EvaluateRegistration(Unaligned(estimate, truth), estimate, truth, TestCamera(), o);
  ASSERT_TRUE(r.lag_frames);
  EXPECT_NEAR(*r.lag_frames, 2.0, 0.05);
  EXPECT_GT(r.lag_samples, 100);
  EXPECT_EQ(r.frames, 0);  // no points: recall and lag only
}

TEST(Registration, RecallCountsALostFrameAsAMiss) {
  const Trajectory truth = WalkThenStill(100, 0);
  Trajectory estimate;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (i % 4 == 3) continue;  // lost
    const double off = i % 2 == 0 ? 0.015 : 0.04;  // within 2 cm, or only within 5 cm
    estimate.push_back({truth[i].timestamp, LookingAlongY(truth[i].pose.Center() + Eigen::Vector3d(off, 0, 0))});
  }
  const RegistrationReport r = EvaluateRegistration(Unaligned(estimate, truth), estimate, truth, TestCamera(), {});
  EXPECT_EQ(r.judged_groundtruth, 99);  // the last ground-truth pose is after the last estimate
  EXPECT_DOUBLE_EQ(r.recall[0].recall, 0.0);
  EXPECT_NEAR(r.recall[1].recall, 50.0 / 99, 1e-12);
  EXPECT_NEAR(r.recall[2].recall, 75.0 / 99, 1e-12);
}

TEST(Registration, PointsBehindEveryCameraAreRefusedNotScoredAsZero) {
  const Trajectory truth = WalkThenStill(30, 0);
  RegistrationOptions o;
  o.points = {{0, -3, 0}};
  EXPECT_THROW(
      {
        try {
          EvaluateRegistration(Unaligned(truth, truth), truth, truth, TestCamera(), o);
        } catch (const RecordingError& e) {
          EXPECT_NE(std::string(e.what()).find("in front of both"), std::string::npos) << e.what();
          throw;
        }
      },
      RecordingError);
}

}  // namespace
}  // namespace arview::recordings
