#include "tracker/absolute_pose.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tracker/refine_pose_ceres_reference.h"
#include "tracker/test_scene.h"

namespace arview::tracker {
namespace {

using testing::MakeScene;
using testing::RefinePoseWithCeres;
using testing::RotationErrorDeg;
using testing::TestCamera;

TEST(PixelThreshold, MatchesAngleOfPixelErrorAtCentre) {
  const double threshold = PixelThresholdToOpenGV(2.0, 500.0);
  EXPECT_NEAR(std::acos(1.0 - threshold), std::atan(2.0 / 500.0), 1e-9);
  EXPECT_LT(PixelThresholdToOpenGV(1.0, 500.0), threshold);
}

TEST(RansacAbsolutePose, ReturnsWorldToCameraPoseNotOpenGVsCameraToWorld) {
  const calib::Camera camera = TestCamera();
  const auto scene = MakeScene(camera, 60, 0.0, 0.0, 3);
  std::vector<Eigen::Vector3d> bearings;
  for (const auto& p : scene.pixels) bearings.push_back(camera.Unproject(p));
  RansacOptions options;
  options.threshold = PixelThresholdToOpenGV(1.0, camera.fx);
  const RansacResult r = RansacAbsolutePose(bearings, scene.points, options);
  ASSERT_TRUE(r.found);
  EXPECT_LT(RotationErrorDeg(r.pose, scene.pose), 1e-6);
  EXPECT_LT((r.pose.t_cw - scene.pose.t_cw).norm(), 1e-6);
  EXPECT_EQ(r.stats.inliers, 60);
}

class SolverTest : public ::testing::TestWithParam<MinimalSolver> {};

TEST_P(SolverTest, RecoversPoseWithNoiseAndOutliers) {
  const calib::Camera camera = TestCamera();
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    const auto scene = MakeScene(camera, 300, 0.7, 0.4, seed);
    AbsolutePoseOptions options;
    options.solver = GetParam();
    options.seed = seed;
    const AbsolutePoseResult r = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
    ASSERT_TRUE(r.ok) << r.reason;
    EXPECT_LT(RotationErrorDeg(r.pose, scene.pose), 0.1) << "seed " << seed;
    EXPECT_LT((r.pose.Center() - scene.pose.Center()).norm(), 0.01) << "seed " << seed;
    EXPECT_LT(r.stats.rms_px, 1.2);
    int true_inliers_found = 0, outliers_accepted = 0;
    for (int i : r.inliers) (scene.is_outlier[i] ? outliers_accepted : true_inliers_found)++;
    int true_inliers = 0;
    for (bool o : scene.is_outlier) true_inliers += !o;
    EXPECT_GE(true_inliers_found, 0.97 * true_inliers);
    // A random pixel lands within 4 px of the truth only by chance (~0.03% of the image).
    EXPECT_LE(outliers_accepted, 3);
  }
}

INSTANTIATE_TEST_SUITE_P(AllSolvers, SolverTest,
                         ::testing::Values(MinimalSolver::kKneip, MinimalSolver::kGao,
                                           MinimalSolver::kEpnp),
                         [](const auto& info) { return ToString(info.param); });

TEST(EstimateAbsolutePose, RefinementImprovesOnRansac) {
  const calib::Camera camera = TestCamera();
  const auto scene = MakeScene(camera, 400, 1.0, 0.2, 11);
  AbsolutePoseOptions options;
  options.refine = false;
  const auto raw = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
  options.refine = true;
  const auto refined = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
  ASSERT_TRUE(raw.ok) << raw.reason;
  ASSERT_TRUE(refined.ok) << refined.reason;
  EXPECT_LT(refined.stats.rms_px, raw.stats.rms_px);
  EXPECT_LT((refined.pose.Center() - scene.pose.Center()).norm(),
            (raw.pose.Center() - scene.pose.Center()).norm());
}

TEST(EstimateAbsolutePose, SameSeedSameResult) {
  const calib::Camera camera = TestCamera();
  const auto scene = MakeScene(camera, 200, 1.0, 0.5, 5);
  AbsolutePoseOptions options;
  options.seed = 42;
  options.refine = false;
  const auto a = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
  const auto b = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
  ASSERT_TRUE(a.ok);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.stats.ransac_iterations, b.stats.ransac_iterations);
  EXPECT_EQ(a.pose.t_cw, b.pose.t_cw);
}

TEST(EstimateAbsolutePose, TooFewCorrespondencesIsLostWithReason) {
  const calib::Camera camera = TestCamera();
  const auto scene = MakeScene(camera, 8, 0.0, 0.0, 2);
  const auto r = EstimateAbsolutePose(camera, scene.pixels, scene.points, {});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.failure, PoseFailure::kTooFewCorrespondences);
  EXPECT_NE(r.reason.find("8 correspondences"), std::string::npos) << r.reason;
}

TEST(EstimateAbsolutePose, CollinearPointsAreDegenerate) {
  const calib::Camera camera = TestCamera();
  const calib::Pose pose = MakeScene(camera, 1, 0, 0, 9).pose;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  const Eigen::Vector3d C = pose.Center();
  const Eigen::Vector3d forward = pose.q_cw.conjugate() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d side = pose.q_cw.conjugate() * Eigen::Vector3d(1, 0.3, 0.1).normalized();
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d X = C + 4.0 * forward + (i - 25) * 0.05 * side;
    points.push_back(X);
    pixels.push_back(camera.Project(pose.ToCamera(X)));
  }
  const auto r = EstimateAbsolutePose(camera, pixels, points, {});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.failure, PoseFailure::kDegenerate) << r.reason;
  EXPECT_NE(r.reason.find("collinear"), std::string::npos);
}

TEST(EstimateAbsolutePose, PureOutliersAreNotAPose) {
  const calib::Camera camera = TestCamera();
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    const auto scene = MakeScene(camera, 300, 0.0, 1.0, 100 + seed);
    AbsolutePoseOptions options;
    options.seed = seed;
    const auto r = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
    EXPECT_FALSE(r.ok) << "seed " << seed << ": " << r.stats.inliers << " inliers";
    EXPECT_FALSE(r.reason.empty());
  }
}

TEST(EstimateAbsolutePose, RejectsMismatchedInput) {
  EXPECT_THROW(EstimateAbsolutePose(TestCamera(), {{1, 2}}, {}, {}), arview::Error);
}

TEST(RefinePose, UsesTheDistortionModel) {
  // Noise-free distorted pixels: starting from a perturbed pose, refinement must land on the
  // truth to far below a pixel, which it cannot if it projected without distortion.
  const calib::Camera camera = TestCamera();
  const auto scene = MakeScene(camera, 100, 0.0, 0.0, 21);
  calib::Pose start = scene.pose;
  start.t_cw += Eigen::Vector3d(0.05, -0.03, 0.04);
  start.q_cw = (start.q_cw * Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY())));
  const RefineResult r = RefinePose(camera, scene.pixels, scene.points, start, {});
  ASSERT_TRUE(r.ok);
  EXPECT_LT(RotationErrorDeg(r.pose, scene.pose), 1e-6);
  EXPECT_LT((r.pose.t_cw - scene.pose.t_cw).norm(), 1e-6);
  for (size_t i = 0; i < scene.pixels.size(); ++i)
    EXPECT_LT(ReprojectionError(camera, r.pose, scene.pixels[i], scene.points[i]), 1e-5);
}

// The hand-written Levenberg-Marquardt must reach the minimum Ceres reaches on the same cost:
// noisy pixels, outliers, each robust loss, a distorted camera, a start 3 degrees and 10 cm off.
TEST(RefinePose, ReachesCeresMinimum) {
  const calib::Camera camera = TestCamera();
  for (RobustLoss loss : {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    for (std::uint32_t seed = 1; seed <= 4; ++seed) {
      const auto scene = MakeScene(camera, 250, 0.8, loss == RobustLoss::kNone ? 0.0 : 0.2, 300 + seed);
      calib::Pose start = scene.pose;
      start.t_cw += Eigen::Vector3d(0.06, -0.05, 0.05);
      start.q_cw = start.q_cw * Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 3).normalized()));
      RefineOptions options;
      options.loss = loss;
      options.max_iterations = 100;
      options.function_tolerance = 1e-15;
      const RefineResult ours = RefinePose(camera, scene.pixels, scene.points, start, options);
      double ceres_cost = 0;
      const calib::Pose ceres = RefinePoseWithCeres(camera, scene.pixels, scene.points, start, options, &ceres_cost);
      ASSERT_TRUE(ours.ok);
      EXPECT_LT(RotationErrorDeg(ours.pose, ceres), 1e-6) << "loss " << static_cast<int>(loss) << " seed " << seed;
      EXPECT_LT((ours.pose.Center() - ceres.Center()).norm(), 1e-7) << "loss " << static_cast<int>(loss) << " seed " << seed;
      EXPECT_NEAR(ours.stats.final_cost, ceres_cost, 1e-9 * ceres_cost + 1e-12);
      EXPECT_TRUE(ours.stats.converged);
      EXPECT_LT(ours.stats.final_cost, ours.stats.initial_cost);
    }
  }
}

// The default options (20 steps, tolerance 1e-8) stop where Ceres' defaults stop, to far below
// what matters: a tenth of a micro-radian, a micrometre at 2-6 m.
TEST(RefinePose, DefaultOptionsStopNearTheMinimum) {
  const calib::Camera camera = TestCamera();
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    const auto scene = MakeScene(camera, 250, 0.5, 0.1, 400 + seed);
    calib::Pose start = scene.pose;
    start.t_cw += Eigen::Vector3d(0.02, 0.01, -0.02);
    const RefineResult ours = RefinePose(camera, scene.pixels, scene.points, start, {});
    RefineOptions tight;
    tight.max_iterations = 100;
    tight.function_tolerance = 1e-15;
    const calib::Pose best = RefinePoseWithCeres(camera, scene.pixels, scene.points, start, tight);
    ASSERT_TRUE(ours.ok);
    EXPECT_LT(RotationErrorDeg(ours.pose, best), 1e-5);
    EXPECT_LT((ours.pose.Center() - best.Center()).norm(), 1e-6);
  }
}

TEST(RefinePose, PointsBehindTheCameraDoNotPullThePoseThroughIt) {
  const calib::Camera camera = TestCamera();
  auto scene = MakeScene(camera, 100, 0.3, 0.0, 31);
  // Ten points moved behind the camera: they keep a constant residual and no gradient.
  const Eigen::Vector3d C = scene.pose.Center();
  for (int i = 0; i < 10; ++i) scene.points[i] = C - (scene.points[i] - C);
  const RefineResult r = RefinePose(camera, scene.pixels, scene.points, scene.pose, {});
  ASSERT_TRUE(r.ok);
  EXPECT_LT(RotationErrorDeg(r.pose, scene.pose), 0.05);
  EXPECT_LT((r.pose.Center() - C).norm(), 0.01);
}

TEST(RefinePose, EmptyOrMismatchedInputIsNotOk) {
  const calib::Camera camera = TestCamera();
  EXPECT_FALSE(RefinePose(camera, {}, {}, {}, {}).ok);
  EXPECT_FALSE(RefinePose(camera, {{1, 2}}, {}, {}, {}).ok);
}

TEST(ParseMinimalSolver, NamesRoundTripAndUnknownThrows) {
  for (auto s : {MinimalSolver::kKneip, MinimalSolver::kGao, MinimalSolver::kEpnp})
    EXPECT_EQ(ParseMinimalSolver(ToString(s)), s);
  EXPECT_THROW(ParseMinimalSolver("p4p"), arview::Error);
}

}  // namespace
}  // namespace arview::tracker
