#include "base/point_spread.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace arview {
namespace {

std::vector<Eigen::Vector3d> Floor(int n, double scale = 1, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.push_back(offset + scale * Eigen::Vector3d(u(rng), 0.01 * u(rng), u(rng)));
  return points;
}

TEST(MeasureSpread, GivesTheStandardDeviationsAlongThePrincipalAxesAtAnyScale) {
  // Four points at (±1, 0, 0), (0, ±2, 0): deviations sqrt(2/4) and sqrt(8/4), largest first.
  const std::vector<Eigen::Vector3d> cross = {{1, 0, 0}, {-1, 0, 0}, {0, 2, 0}, {0, -2, 0}};
  for (const double scale : {1.0, 1e-300, 1e250}) {
    std::vector<Eigen::Vector3d> scaled;
    for (const auto& p : cross) scaled.push_back(scale * p + Eigen::Vector3d(0, 0, 5 * scale));
    const PointSpread s = MeasureSpread(scaled);
    EXPECT_NEAR(s.sigma[0] / scale, std::sqrt(2.0), 1e-12) << scale;
    EXPECT_NEAR(s.sigma[1] / scale, std::sqrt(0.5), 1e-12) << scale;
    EXPECT_NEAR(s.sigma[2] / scale, 0, 1e-12) << scale;
    EXPECT_NEAR(s.mean.z() / scale, 5, 1e-12) << scale;
  }
  EXPECT_EQ(MeasureSpread({}).sigma, Eigen::Vector3d::Zero());
}

TEST(WhyNotAPlane, AcceptsRealFloorsFarFromTheOriginOrSmall) {
  EXPECT_EQ(WhyNotAPlane(Floor(100), "points"), std::nullopt);
  EXPECT_EQ(WhyNotAPlane(Floor(100, 1000, {1e6, 2e6, 0}), "points"), std::nullopt);  // millimetres, far away
  EXPECT_EQ(WhyNotAPlane(Floor(100, 1e-50), "points"), std::nullopt);
}

// Issue 41: the degeneracy tests are absolute as well as relative.
TEST(WhyNotAPlane, SaysWhatIsDegenerate) {
  std::vector<Eigen::Vector3d> one_point(40, Eigen::Vector3d(1, 2, 3));
  for (size_t i = 0; i < one_point.size(); ++i) one_point[i].x() += (i % 3) * 1e-16;  // rounding-level scatter
  auto why = WhyNotAPlane(one_point, "points");
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("all 40 points lie at one point, (1, 2, 3): they spread ", 0), 0u) << *why;
  EXPECT_NE(why->find("within the rounding of numbers of that size"), std::string::npos) << *why;

  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 30; ++i) line.emplace_back(i, 2.0 * i, -1.0 * i);
  why = WhyNotAPlane(line, "points");
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("all 30 points lie on one line: they spread ", 0), 0u) << *why;

  // A floor scaled by 1e-300: every square underflows. Its spread is below the floor of 1e-100.
  why = WhyNotAPlane(Floor(50, 1e-300), "points");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("below 1e-100, the least spread arview computes with"), std::string::npos) << *why;

  std::vector<Eigen::Vector3d> far = Floor(10);
  far[4].y() = std::numeric_limits<double>::quiet_NaN();
  why = WhyNotAPlane(far, "positions");
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("position 4 is (", 0), 0u) << *why;
  EXPECT_NE(why->find("nan"), std::string::npos) << *why;
  far[4].y() = 1e200;
  ASSERT_TRUE(WhyNotAPlane(far, "positions"));
  EXPECT_EQ(*WhyNotAPlane({{0, 0, 0}, {1, 0, 0}}, "points"), "only 2 points (a plane needs 3)");
}

}  // namespace
}  // namespace arview
