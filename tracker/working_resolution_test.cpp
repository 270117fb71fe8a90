#include "tracker/working_resolution.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tracker/residual_gate.h"
#include "tracker/tracker.h"
#include "tracker/tracker_internal.h"

namespace arview::tracker {
namespace {

calib::Camera PhoneCamera() {  // phone-fox's calibration (1080x1920, distorted)
  calib::Camera c = calib::Camera::Pinhole(1080, 1920, 1375.52, 1374.49, 554.558, 965.268);
  c.dist = {0.0578421, -0.0805099, -0.000980296, 0.00015575, 0};
  return c;
}

TEST(WorkingResolution, ReducesTheLongestSideAndKeepsSmallerFrames) {
  const WorkingResolution phone(PhoneCamera(), 960);
  EXPECT_TRUE(phone.reduced());
  EXPECT_EQ(phone.work().width, 540);
  EXPECT_EQ(phone.work().height, 960);
  const WorkingResolution vga(calib::Camera::Pinhole(640, 480, 500, 500, 320, 240), 960);
  EXPECT_FALSE(vga.reduced());
  EXPECT_EQ(vga.work().width, 640);
  EXPECT_FALSE(WorkingResolution(PhoneCamera(), 0).reduced());
}

// A point projected by the scaled camera, mapped back to full resolution, is where the full
// camera projects it: the scaling is exact, distortion included, with OpenCV's pixel centres.
TEST(WorkingResolution, ScaledCameraProjectsWhereTheFullCameraDoes) {
  for (int long_side : {960, 720, 640, 333}) {
    const WorkingResolution r(PhoneCamera(), long_side);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.3, -0.5, 1.2),
                                    Eigen::Vector3d(-0.35, 0.6, 1.0)}) {
      const Eigen::Vector2d full = r.full().Project(p);
      const Eigen::Vector2d back = r.ToFull(r.work().Project(p));
      EXPECT_NEAR((full - back).norm(), 0.0, 1e-9) << "long side " << long_side;
    }
  }
}

// The principal point follows the pixel-centre convention: halving a 4x4 image maps the centre
// of full pixels (0.5, 0.5) (the corner between the first four) to the centre of working pixel
// (0, 0); a naive cx·s would be off by a quarter of a working pixel.
TEST(WorkingResolution, PrincipalPointKeepsOpenCvPixelCentres) {
  const calib::Camera full = calib::Camera::Pinhole(4, 4, 10, 10, 0.5, 0.5);
  const calib::Camera half = ScaleCamera(full, 2, 2);
  EXPECT_DOUBLE_EQ(half.cx, 0.0);
  EXPECT_DOUBLE_EQ(half.cy, 0.0);
  EXPECT_DOUBLE_EQ(half.fx, 5.0);
  // And INTER_AREA agrees: a bright 2x2 block at the top-left becomes working pixel (0, 0).
  cv::Mat image = cv::Mat::zeros(4, 4, CV_8U);
  image(cv::Rect(0, 0, 2, 2)).setTo(200);
  const cv::Mat reduced = WorkingResolution(full, 2).Reduce(image);
  EXPECT_EQ(reduced.at<std::uint8_t>(0, 0), 200);
  EXPECT_EQ(reduced.at<std::uint8_t>(1, 1), 0);
}

TEST(ResidualGate, FollowsTheObservedScaleWithinItsBounds) {
  ResidualGateOptions o;
  ResidualGate gate(o);
  EXPECT_DOUBLE_EQ(gate.Gate(), 1.5);
  for (int i = 0; i < 40; ++i) gate.Observe(0.9);  // a noisier camera: the gate opens
  EXPECT_NEAR(gate.Gate(), 1.8, 1e-12);
  for (int i = 0; i < 40; ++i) gate.Observe(5.0);  // never beyond the upper bound
  EXPECT_DOUBLE_EQ(gate.Gate(), o.max_px);
  for (int i = 0; i < 40; ++i) gate.Observe(0.2);  // a clean camera: tight, but not below min_px
  EXPECT_DOUBLE_EQ(gate.Gate(), o.min_px);
  gate.Observe(std::nan(""));
  EXPECT_DOUBLE_EQ(gate.Gate(), o.min_px);
}

// A few clean frames do not close the gate below its initial 1.5 px: their median is no robust
// scale yet.
TEST(ResidualGate, StaysAtItsInitialScaleUntilEnoughFramesWereSeen) {
  ResidualGateOptions o;
  ResidualGate gate(o);
  for (int i = 1; i < o.min_observations; ++i) {
    gate.Observe(0.4);
    EXPECT_DOUBLE_EQ(gate.Gate(), 1.5) << i << " frames";
  }
  gate.Observe(0.4);
  EXPECT_DOUBLE_EQ(gate.Gate(), o.min_px);
  ResidualGate noisy(o);  // a noisier camera opens it at once
  noisy.Observe(1.0);
  EXPECT_DOUBLE_EQ(noisy.Gate(), 2.0);
}

// One outlier frame moves a median gate by nothing.
TEST(ResidualGate, OneBadFrameDoesNotOpenTheGate) {
  ResidualGate gate;
  for (int i = 0; i < 29; ++i) gate.Observe(0.6);
  gate.Observe(2.4);
  EXPECT_NEAR(gate.Gate(), 1.2, 1e-12);
}

TEST(ScaleMotion, DoublesAndHalvesAMotion) {
  const calib::Pose m{Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())), {0.02, 0, 0.01}};
  const calib::Pose twice = ScaleMotion(m, 2.0);
  EXPECT_NEAR(twice.q_cw.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()))), 0,
              1e-12);
  EXPECT_NEAR((twice.t_cw - Eigen::Vector3d(0.04, 0, 0.02)).norm(), 0, 1e-12);
  const calib::Pose once = ScaleMotion(m, 1.0);
  EXPECT_NEAR(once.q_cw.angularDistance(m.q_cw), 0, 1e-12);
}

TEST(RelocalizerFeatures, TheReducedRegimeHasItsOwnSettings) {
  RelocalizerOptions options;
  options.features.contrast_threshold = 0.02;
  options.reduced_features.contrast_threshold = 0.03;
  EXPECT_EQ(ActiveFeatures(PhoneCamera(), options).contrast_threshold, 0.03);  // 1920 > 640
  const calib::Camera vga = calib::Camera::Pinhole(640, 480, 500, 500, 320, 240);
  EXPECT_EQ(ActiveFeatures(vga, options).contrast_threshold, 0.02);  // seen at its own size
  options.sift_long_side = 0;                                         // the working frame
  EXPECT_EQ(ActiveFeatures(PhoneCamera(), options).contrast_threshold, 0.02);
}

TEST(RelocalizerFeatures, StrongestKeepsTheStrongestInTheirOrderWithTheirDescriptors) {
  Features all;
  const float responses[] = {0.5f, 0.9f, 0.1f, 0.9f, 0.7f};
  all.descriptors = cv::Mat(5, 128, CV_8U);
  for (int i = 0; i < 5; ++i) {
    all.keypoints.emplace_back(cv::Point2f(static_cast<float>(i), 0.f), 1.f, -1.f, responses[i]);
    all.descriptors.row(i).setTo(i);
  }
  const Features strongest = StrongestFeatures(all, 3);
  ASSERT_EQ(strongest.keypoints.size(), 3u);
  ASSERT_EQ(strongest.descriptors.rows, 3);
  const int expected[] = {1, 3, 4};  // 0.9, 0.9, 0.7, in their original order
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(strongest.keypoints[i].pt.x, static_cast<float>(expected[i]));
    EXPECT_EQ(strongest.descriptors.at<uint8_t>(i, 127), expected[i]);
  }
  EXPECT_EQ(StrongestFeatures(all, 5).keypoints.size(), 5u);
  EXPECT_EQ(StrongestFeatures(all, 0).keypoints.size(), 5u);  // 0: all
}

}  // namespace
}  // namespace arview::tracker
