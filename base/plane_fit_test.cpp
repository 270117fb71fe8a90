#include "base/plane_fit.h"

#include <gtest/gtest.h>

#include <random>

#include "base/error.h"

namespace arview {
namespace {

TEST(FitDominantPlane, FindsAFloorUnderClutterAndCountsItsInliers) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 300; ++i) points.emplace_back(u(rng), 0.2 + 0.001 * u(rng), u(rng));  // y = 0.2
  for (int i = 0; i < 100; ++i) points.emplace_back(u(rng), 0.2 + std::abs(u(rng)), u(rng));  // clutter above
  PlaneFitOptions o;
  o.middle_fraction = 10;  // every point takes part (and is counted)
  const Plane p = FitDominantPlane(points, o);
  EXPECT_GT(std::abs(p.normal.y()), 0.999);
  EXPECT_NEAR(std::abs(p.Distance(Eigen::Vector3d::Zero())), 0.2, 0.002);
  EXPECT_GE(p.inliers, 300);  // the floor's points, and clutter within the 1% threshold of it
  EXPECT_LT(p.inliers, 330);
}

TEST(FitDominantPlane, AnUpPriorRejectsAWallThatHoldsMorePoints) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 400; ++i) points.emplace_back(0.0, u(rng), u(rng));       // wall x = 0
  for (int i = 0; i < 200; ++i) points.emplace_back(u(rng), -0.5, u(rng));      // floor y = -0.5
  PlaneFitOptions o;
  o.middle_fraction = 10;  // all points
  EXPECT_GT(std::abs(FitDominantPlane(points, o).normal.x()), 0.999);
  o.up_prior = Eigen::Vector3d::UnitY();
  EXPECT_GT(std::abs(FitDominantPlane(points, o).normal.y()), 0.999);
}

TEST(FitDominantPlane, TooFewOrCollinearPointsThrow) {
  EXPECT_THROW(FitDominantPlane({{0, 0, 0}, {1, 0, 0}}, {}), Error);
  EXPECT_THROW(FitDominantPlane({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}, {}), Error);
}

TEST(ComponentMedian, UsesTheOneMedianDefinition) {
  const std::vector<Eigen::Vector3d> p{{0, 0, 0}, {1, 10, 3}, {2, 20, 1}, {3, 30, 2}};
  EXPECT_EQ(ComponentMedian(p), Eigen::Vector3d(1.5, 15, 1.5));
  EXPECT_DOUBLE_EQ(MedianDistance(p, Eigen::Vector3d(0, 0, 0)), 0.5 * (Eigen::Vector3d(1, 10, 3).norm() + Eigen::Vector3d(2, 20, 1).norm()));
}

}  // namespace
}  // namespace arview
