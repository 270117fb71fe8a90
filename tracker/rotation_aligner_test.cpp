#include "tracker/rotation_aligner.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <memory>

#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"
#include "tracker/test_scene.h"

namespace arview::tracker {
namespace {

using testing::LookAt;
using testing::PlanarWorld;
using testing::TestCamera;

const char* kGraffiti = "/usr/share/doc/opencv-doc/examples/data/graf1.png";

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180.0 / M_PI;
}

// The camera 0.9 m in front of the graffiti plane, turned by `yaw_deg` about its own vertical
// axis and `pitch_deg` about its horizontal one (a pure rotation about its centre).
calib::Pose Turned(double yaw_deg, double pitch_deg) {
  const calib::Pose straight = LookAt({0, 0, -0.9}, {0, 0, 0});
  const Eigen::Quaterniond turn = Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY());
  calib::Pose pose = straight;
  pose.q_cw = turn * straight.q_cw;
  pose.t_cw = -(pose.q_cw * straight.Center());
  return pose;
}

// A frame exposed while the camera turned from yaw a to yaw b (degrees): the mean of `samples`
// renders spread evenly over the exposure, as a camera integrates the light.
cv::Mat SmearedFrame(const PlanarWorld& world, double yaw_a, double yaw_b, double pitch, int samples) {
  cv::Mat sum = cv::Mat::zeros(world.camera().Size(), CV_32F);
  for (int s = 0; s < samples; ++s) {
    const double t = (s + 0.5) / samples;
    cv::Mat render;
    world.Render(Turned(yaw_a + t * (yaw_b - yaw_a), pitch)).convertTo(render, CV_32F);
    sum += render;
  }
  cv::Mat out;
  sum.convertTo(out, CV_8U, 1.0 / samples);
  return out;
}

class RotationAlignerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(kGraffiti, "Debian package opencv-doc");
    world_ = std::make_unique<PlanarWorld>(cv::imread(kGraffiti), TestCamera(), 0.0015);
  }
  SmallImage Small(const cv::Mat& gray) const { return SmallImage(gray, world_->camera(), options_); }
  static Eigen::Quaterniond Truth(const calib::Pose& reference, const calib::Pose& current) {
    return current.q_cw * reference.q_cw.conjugate();
  }
  std::unique_ptr<PlanarWorld> world_;
  RotationAlignerOptions options_;
};

// Sharp to sharp, a few degrees apart, started from no rotation at all.
TEST_F(RotationAlignerTest, FindsTheRotationBetweenSharpFrames) {
  const calib::Pose a = Turned(0, 0), b = Turned(4, -2);
  const RotationAlignment r =
      AlignRotation(Small(world_->Render(a)), Small(world_->Render(b)), Eigen::Quaterniond::Identity(), options_);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_LT(AngleDeg(r.rotation, Truth(a, b)), 0.1) << "zncc " << r.zncc;
  EXPECT_GT(r.zncc, 0.95);
  EXPECT_GT(r.overlap, 0.7);
}

// A whip-pan: each frame smeared over 6 degrees (~55 px at 640x480, about what 320 deg/s over a
// 1/60 s exposure does), the frames 8 degrees apart, the prediction 3 degrees off. The rotation
// found is the one at the middle of the exposures within half a small-image pixel (0.9 degrees
// at 80 px wide): the distorted lens smears a point by different amounts where the two frames
// see it, which biases the alignment by ~0.3 degrees (0.2 at 160 px wide, at 4x the cost).
TEST_F(RotationAlignerTest, FindsTheRotationBetweenFramesSmearedByAFastTurn) {
  const cv::Mat ref_frame = SmearedFrame(*world_, -3, 3, 1, 24);
  const cv::Mat cur_frame = SmearedFrame(*world_, 5, 11, 1, 24);
  const Eigen::Quaterniond truth = Truth(Turned(0, 1), Turned(8, 1));
  const Eigen::Quaterniond predicted = Truth(Turned(0, 1), Turned(11, 1));
  const RotationAlignment r = AlignRotation(Small(ref_frame), Small(cur_frame), predicted, options_);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_LT(AngleDeg(r.rotation, truth), 0.4) << "zncc " << r.zncc << " iterations " << r.iterations << " overlap " << r.overlap;
  EXPECT_LT(AngleDeg(r.rotation, truth), AngleDeg(predicted, truth) / 5);
}

TEST_F(RotationAlignerTest, RefusesABlankFrame) {
  const cv::Mat blank(world_->camera().Size(), CV_8U, cv::Scalar(128));
  const RotationAlignment r =
      AlignRotation(Small(world_->Render(Turned(0, 0))), Small(blank), Eigen::Quaterniond::Identity(), options_);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("contrast"), std::string::npos) << r.reason;
}

TEST_F(RotationAlignerTest, RefusesAFrameOfAnotherScene) {
  const cv::Mat other = cv::imread("/usr/share/doc/opencv-doc/examples/data/fruits.jpg", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(other.empty());
  cv::Mat resized;
  cv::resize(other, resized, world_->camera().Size());
  const RotationAlignment r =
      AlignRotation(Small(world_->Render(Turned(0, 0))), Small(resized), Eigen::Quaterniond::Identity(), options_);
  EXPECT_FALSE(r.ok) << "zncc " << r.zncc;
  EXPECT_FALSE(r.reason.empty());
}

TEST_F(RotationAlignerTest, RefusesFramesThatShareTooLittleOfTheView) {
  // 40 degrees apart, started at the truth: the frames share about 40 % of the view, too little
  // to hold the alignment (it slides off the truth) or to trust it.
  const calib::Pose a = Turned(0, 0), b = Turned(40, 0);
  const RotationAlignment r =
      AlignRotation(Small(world_->Render(a)), Small(world_->Render(b)), Truth(a, b), options_);
  EXPECT_FALSE(r.ok) << "zncc " << r.zncc << " overlap " << r.overlap;
  EXPECT_FALSE(r.reason.empty());
}

TEST(SmallImage, EmptyOrWrongTypeGivesNoLevels) {
  RotationAlignerOptions options;
  EXPECT_TRUE(SmallImage(cv::Mat(), TestCamera(), options).empty());
  EXPECT_TRUE(SmallImage(cv::Mat(480, 640, CV_32F, cv::Scalar(0)), TestCamera(), options).empty());
  const SmallImage small(cv::Mat(480, 640, CV_8U, cv::Scalar(7)), TestCamera(), options);
  ASSERT_EQ(small.levels().size(), 2u);
  EXPECT_EQ(small.levels()[0].image.cols, 80);
  EXPECT_EQ(small.levels()[0].image.rows, 60);
  EXPECT_EQ(small.levels()[1].image.cols, 40);
  EXPECT_NEAR(small.contrast(), 0.0, 1e-9);
  EXPECT_FALSE(AlignRotation(small, small, Eigen::Quaterniond::Identity(), options).ok);
}

}  // namespace
}  // namespace arview::tracker
