#include "mapping/self_calibration.h"

#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace arview::mapping {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// F = K⁻ᵀ E K⁻¹ with E = [t]ₓ R of camera b relative to camera a (x_b = R x_a + t); `noise` is
// added to each entry of E (of norm 1), as an epipolar geometry estimated from matches errs.
FundamentalPair ExactPair(const Eigen::Matrix3d& K, std::mt19937* rng, double noise) {
  std::normal_distribution<double> n(0, 1);
  const Eigen::Vector3d axis = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)).normalized();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.05 + 0.3 * std::abs(n(*rng)), axis).toRotationMatrix();
  const Eigen::Vector3d t(n(*rng), 0.3 * n(*rng), 0.2 * n(*rng));
  Eigen::Matrix3d E = Skew(t) * R;
  E /= E.norm();
  for (int i = 0; i < 9; ++i) E(i) += noise * n(*rng);
  return {1, 2, 500, K.inverse().transpose() * E * K.inverse()};
}

TEST(SelfCalibration, TheFocalLengthIsFoundFromExactAndNoisyFundamentalMatrices) {
  // phone-fox's camera: 1080x1920, f 1375 (COLMAP pixels: principal point + 0.5).
  Eigen::Matrix3d K;
  K << 1375, 0, 540, 0, 1375, 960, 0, 0, 1;
  std::mt19937 rng(7);
  std::vector<FundamentalPair> exact, noisy;
  for (int i = 0; i < 40; ++i) exact.push_back(ExactPair(K, &rng, 0));
  for (int i = 0; i < 40; ++i) noisy.push_back(ExactPair(K, &rng, 2e-3));
  const auto from_exact = FocalFromFundamentalMatrices(exact, 1080, 1920, 540, 960);
  ASSERT_TRUE(from_exact);
  EXPECT_NEAR(from_exact->focal_px, 1375, 0.01);
  EXPECT_EQ(from_exact->pairs, 40);
  EXPECT_LT(from_exact->median_cost, 1e-6);
  const auto from_noisy = FocalFromFundamentalMatrices(noisy, 1080, 1920, 540, 960);
  ASSERT_TRUE(from_noisy);
  EXPECT_NEAR(from_noisy->focal_px, 1375, 1375 * 0.02);
}

TEST(SelfCalibration, TooFewPairsGiveNoEstimate) {
  Eigen::Matrix3d K;
  K << 800, 0, 320, 0, 800, 240, 0, 0, 1;
  std::mt19937 rng(3);
  std::vector<FundamentalPair> pairs;
  for (int i = 0; i < kMinSelfCalibrationPairs - 1; ++i) pairs.push_back(ExactPair(K, &rng, 0));
  EXPECT_FALSE(FocalFromFundamentalMatrices(pairs, 640, 480, 320, 240));
}

TEST(SelfCalibration, ImplausibleIntrinsicsAreNamedAndAPhonesAreNot) {
  calib::Camera phone = calib::Camera::Pinhole(1080, 1920, 1375.5, 1374.5, 554.6, 965.3);
  phone.dist = {0.0578, -0.0805, 0, 0, 0};
  EXPECT_TRUE(ImplausibleIntrinsics(phone).empty());
  calib::Camera fisheye_focal = phone;
  fisheye_focal.fx = fisheye_focal.fy = 300;  // 145° across 1920 px
  fisheye_focal.dist = {0, 0, 0, 0, 0};
  ASSERT_EQ(ImplausibleIntrinsics(fisheye_focal).size(), 1u);
  EXPECT_NE(ImplausibleIntrinsics(fisheye_focal)[0].find("focal length 300 px"), std::string::npos);
  calib::Camera folding = phone;
  folding.dist = {-0.9, 0, 0, 0, 0};  // r(1 - 0.9 r²) turns back at r = 0.61, inside the corners (0.79)
  ASSERT_EQ(ImplausibleIntrinsics(folding).size(), 1u);
  EXPECT_NE(ImplausibleIntrinsics(folding)[0].find("folds back"), std::string::npos);
  calib::Camera off_centre = phone;
  off_centre.cx = 1000;
  ASSERT_EQ(ImplausibleIntrinsics(off_centre).size(), 1u);
  EXPECT_NE(ImplausibleIntrinsics(off_centre)[0].find("principal point"), std::string::npos);
}

}  // namespace
}  // namespace arview::mapping
