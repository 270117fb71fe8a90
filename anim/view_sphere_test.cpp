#include "anim/character.h"
#include "anim/view_sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

namespace arview::anim {
namespace {

std::vector<Eigen::Vector3d> Ring(int n, double offset_deg = 0, double span_deg = 360) {
  std::vector<Eigen::Vector3d> keys;
  for (int i = 0; i < n; ++i)
    keys.push_back(DirectionFromAzimuthElevation(offset_deg + span_deg * i / (span_deg >= 360 ? n : n - 1), 0));
  return keys;
}

std::vector<Eigen::Vector3d> CubeCorners() {
  std::vector<Eigen::Vector3d> keys;
  for (int x : {-1, 1})
    for (int y : {-1, 1})
      for (int z : {-1, 1}) keys.emplace_back(x, y, z);
  return keys;
}

std::vector<Eigen::Vector3d> Octahedron() {
  return {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
          -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
}

std::vector<Eigen::Vector3d> Cap() {  // front cap: neither spanning nor a ring
  return {DirectionFromAzimuthElevation(0, 0), DirectionFromAzimuthElevation(40, 10),
          DirectionFromAzimuthElevation(-40, 10), DirectionFromAzimuthElevation(0, 40)};
}

void ExpectConvex(std::span<const double> w) {
  for (double x : w) EXPECT_GE(x, 0.0);
  EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-12);
}

// A dense path over the whole sphere: a loxodrome from pole to pole plus the horizon circle
// and a few tilted great circles. Returns the largest change of any weight between steps.
double LargestJump(const ViewSphere& s, int steps) {
  std::vector<Eigen::Vector3d> path;
  for (int i = 0; i <= steps; ++i) {
    const double t = double(i) / steps;
    const double el = -89.9 + 179.8 * t, az = 360.0 * 12 * t;
    path.push_back(DirectionFromAzimuthElevation(az, el));
  }
  for (double tilt : {0.0, 17.0, 45.0, 71.0}) {
    const Eigen::Vector3d axis = DirectionFromAzimuthElevation(33, 90 - tilt);
    const Eigen::Vector3d x = axis.unitOrthogonal(), y = axis.cross(x);
    for (int i = 0; i <= steps / 4; ++i) {
      const double a = 2 * M_PI * i / (steps / 4);
      path.push_back(std::cos(a) * x + std::sin(a) * y);
    }
  }
  std::vector<double> prev(s.size()), cur(s.size());
  s.Weights(path[0], prev);
  double worst = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    if ((path[i] - path[i - 1]).norm() > 0.1) {  // a new sub-path starts
      s.Weights(path[i], prev);
      continue;
    }
    s.Weights(path[i], cur);
    ExpectConvex(cur);
    for (int k = 0; k < s.size(); ++k) worst = std::max(worst, std::abs(cur[k] - prev[k]));
    std::swap(prev, cur);
  }
  return worst;
}

TEST(ViewSphere, Eq2MatchesFormula) {
  const auto keys = Ring(8);
  const Eigen::Vector3d v = DirectionFromAzimuthElevation(10, 20);
  for (auto kind : {DistanceKind::kGeodesic, DistanceKind::kChordal}) {
    ViewSphere s(keys, {WeightingMode::kInverseDistance, kind, 2.5});
    std::vector<double> w(8);
    s.Weights(v, w);
    std::vector<double> expect(8);
    double sum = 0;
    for (int k = 0; k < 8; ++k) {
      const double d = kind == DistanceKind::kGeodesic ? std::acos(v.dot(keys[k])) : (v - keys[k]).norm();
      sum += expect[k] = std::pow(d, -2.5);
    }
    for (int k = 0; k < 8; ++k) EXPECT_NEAR(w[k], expect[k] / sum, 1e-12);
    ExpectConvex(w);
  }
}

TEST(ViewSphere, ExactHitAndTies) {
  std::vector<Eigen::Vector3d> keys = Ring(4);
  keys.push_back(keys[1]);  // two keys at the same viewpoint (two animations)
  for (auto mode : {WeightingMode::kInverseDistance, WeightingMode::kLocalSupport}) {
    ViewSphere s(keys, {mode, DistanceKind::kGeodesic, 3});
    std::vector<double> w(5);
    s.Weights(keys[0] * 2.0, w);
    EXPECT_DOUBLE_EQ(w[0], 1.0);
    s.Weights(keys[1], w);
    EXPECT_DOUBLE_EQ(w[1], 0.5);
    EXPECT_DOUBLE_EQ(w[4], 0.5);
    for (double x : w) EXPECT_TRUE(std::isfinite(x));
  }
}

TEST(ViewSphere, ZeroViewpointGivesEqualWeights) {
  ViewSphere s(Ring(4));
  std::vector<double> w(4);
  s.Weights(Eigen::Vector3d::Zero(), w);
  for (double x : w) EXPECT_DOUBLE_EQ(x, 0.25);
}

TEST(ViewSphere, ZeroLengthKeyIsAnError) {
  try {
    ViewSphere s({Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero()});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key viewpoint 1 (0, 0, 0) is 0 long, below 1e-09: too short to give a direction"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ViewSphere({}), Error);
  EXPECT_THROW(ViewSphere(Ring(3), {WeightingMode::kInverseDistance, DistanceKind::kGeodesic, 0.0}), Error);
}

TEST(ViewSphere, LayoutDetection) {
  const ViewSphereOptions local{WeightingMode::kLocalSupport, DistanceKind::kGeodesic, 3};
  EXPECT_EQ(ViewSphere(Ring(8), local).layout(), ViewSphere::Layout::kRing);
  EXPECT_EQ(ViewSphere(Ring(5, -90, 180), local).layout(), ViewSphere::Layout::kRing);
  EXPECT_EQ(ViewSphere(Octahedron(), local).layout(), ViewSphere::Layout::kSpanning);
  EXPECT_EQ(ViewSphere(Octahedron(), local).triangles().size(), 8u);
  // Cube corners: six square faces, each split in two.
  EXPECT_EQ(ViewSphere(CubeCorners(), local).triangles().size(), 12u);
  EXPECT_EQ(ViewSphere(Cap(), local).layout(), ViewSphere::Layout::kOther);
}

TEST(ViewSphere, LocalSupportUsesOnlyNearestKeys) {
  const ViewSphereOptions local{WeightingMode::kLocalSupport, DistanceKind::kGeodesic, 3};
  {
    ViewSphere s(Octahedron(), local);
    std::vector<double> w(6);
    const Eigen::Vector3d v(1, 2, 3);
    s.Weights(v, w);
    EXPECT_EQ(w[1] + w[3] + w[5], 0.0);  // only +X, +Y, +Z
    // Barycentric on the plane x+y+z=1, gnomonic: proportional to the coordinates.
    EXPECT_NEAR(w[0], 1.0 / 6, 1e-12);
    EXPECT_NEAR(w[2], 2.0 / 6, 1e-12);
    EXPECT_NEAR(w[4], 3.0 / 6, 1e-12);
  }
  {
    ViewSphere s(Ring(8), local);
    std::vector<double> w(8);
    s.Weights(DirectionFromAzimuthElevation(45 + 11.25, 10), w);
    EXPECT_NEAR(w[1], 0.75, 1e-12);
    EXPECT_NEAR(w[2], 0.25, 1e-12);
    int nonzero = 0;
    for (double x : w) nonzero += x > 0;
    EXPECT_EQ(nonzero, 2);
  }
}

TEST(ViewSphere, PartialRingFallsBackToEq2BehindIt) {
  const ViewSphereOptions local{WeightingMode::kLocalSupport, DistanceKind::kGeodesic, 3};
  ViewSphere s(Ring(5, -90, 180), local);
  ViewSphere eq2(Ring(5, -90, 180), {WeightingMode::kInverseDistance, DistanceKind::kGeodesic, 3});
  std::vector<double> w(5), e(5);
  const Eigen::Vector3d behind = DirectionFromAzimuthElevation(180, 0);
  s.Weights(behind, w);
  eq2.Weights(behind, e);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(w[k], e[k], 1e-12);
}

TEST(ViewSphere, ContinuousAlongDensePaths) {
  const std::vector<std::vector<Eigen::Vector3d>> layouts = {Ring(8), Ring(5, -90, 180), Octahedron(), CubeCorners(),
                                                             Cap(), Ring(2, 0, 90)};
  for (auto mode : {WeightingMode::kInverseDistance, WeightingMode::kLocalSupport})
    for (auto kind : {DistanceKind::kGeodesic, DistanceKind::kChordal})
      for (std::size_t l = 0; l < layouts.size(); ++l) {
        SCOPED_TRACE("layout " + std::to_string(l) + " mode " + std::to_string(int(mode)) + " kind " + std::to_string(int(kind)));
        ViewSphere s(layouts[l], {mode, kind, 3});
        const double coarse = LargestJump(s, 20000), fine = LargestJump(s, 80000);
        // A discontinuity would not shrink with the step; a continuous map shrinks about 4x.
        EXPECT_LT(coarse, 0.05) << "layout " << l << " mode " << int(mode);
        EXPECT_LT(fine, 0.5 * coarse + 1e-9) << "layout " << l << " mode " << int(mode);
      }
}

TEST(ViewSphere, AzimuthElevation) {
  EXPECT_LT((DirectionFromAzimuthElevation(0, 0) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_LT((DirectionFromAzimuthElevation(90, 0) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_LT((DirectionFromAzimuthElevation(0, 90) - Eigen::Vector3d::UnitY()).norm(), 1e-12);
}

}  // namespace
}  // namespace arview::anim

namespace arview::anim {
namespace {

// Issue 41: a key 1e300 long normalised to (0, 0, 0) and was called "zero length"; a denormal
// one was too. Each is said for what it is; huge and tiny ordinary lengths are directions.
TEST(UnitDirection, SaysWhyAVectorGivesNoDirection) {
  auto why = [](const Eigen::Vector3d& v) -> std::string {
    try {
      UnitDirection(v);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(why({1e300, 1e300, 1e300}), "(1e+300, 1e+300, 1e+300) is 1.73e+300 long, beyond 1e+12 (a direction such as [0, 0, 1] is expected)");
  EXPECT_EQ(why({5e-324, 0, 0}), "(4.94066e-324, 0, 0) is 4.94e-324 long, below 1e-09: too short to give a direction");
  EXPECT_EQ(why({0, std::nan(""), 0}), "(0, nan, 0) is not finite");
  EXPECT_LT((UnitDirection({0, 1e12, 0}) - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_LT((UnitDirection({-1e-9, 0, 0}) + Eigen::Vector3d::UnitX()).norm(), 1e-15);
  EXPECT_NEAR(UnitDirection({3, 4, 12}).norm(), 1.0, 1e-15);
}

}  // namespace
}  // namespace arview::anim
