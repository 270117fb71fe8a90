// The overlay: key dots land where the sphere's directions project, in their weight's colour.

#include <gtest/gtest.h>

#include "render/hud.h"

namespace arview::render {
namespace {

calib::Pose LookingAlongZ(double distance) {
  // Camera at (0, 0, -distance) looking at the origin along +z, OpenCV axes (y down).
  return calib::Pose::FromRt(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, distance));
}

double ColourDistance(const cv::Vec3b& a, const cv::Scalar& b) {
  return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
}

TEST(Hud, WeightColourRampIsMonotoneInGreenAndClamped) {
  EXPECT_LT(WeightColour(0)[1], WeightColour(0.5)[1]);
  EXPECT_LT(WeightColour(0.5)[2], WeightColour(1)[2]);
  EXPECT_EQ(WeightColour(-1), WeightColour(0));
  EXPECT_EQ(WeightColour(7), WeightColour(1));
}

TEST(Hud, KeysAreDrawnAtTheirProjectionsInTheirWeightColour) {
  const calib::Camera camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  const calib::Pose pose = LookingAlongZ(5);
  HudSphere s;
  s.name = "test";
  s.radius = 1;
  // Keys left and right of the centre (x = ±1 on the sphere), facing the camera sideways.
  s.keys = {{Eigen::Vector3d(1, 0, 0), 0.9, "A", false}, {Eigen::Vector3d(-1, 0, 0), 0.1, "B", false}};
  s.viewpoint = Eigen::Vector3d(0, 0, -1);  // toward the camera
  cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  DrawHud(frame, camera, pose, {s}, {});
  for (const HudKey& key : s.keys) {
    cv::Point2d px;
    ASSERT_TRUE(ProjectOnSphere(s, key.direction, camera, pose, &px));
    const cv::Vec3b got = frame.at<cv::Vec3b>(static_cast<int>(std::lround(px.y)), static_cast<int>(std::lround(px.x)));
    EXPECT_LT(ColourDistance(got, WeightColour(key.weight)), 12) << key.label << " " << got;
  }
  cv::Point2d view;
  ASSERT_TRUE(ProjectOnSphere(s, s.viewpoint, camera, pose, &view));
  EXPECT_NEAR(view.x, 319.5, 1e-9);
  const cv::Vec3b red = frame.at<cv::Vec3b>(240, 320);
  EXPECT_GT(red[2], 200);
  EXPECT_LT(red[1], 80);
  // The weight panel is at the top right: something was drawn there, nothing at the bottom left.
  EXPECT_GT(cv::sum(frame(cv::Rect(400, 10, 230, 40)))[0], 1000);
  EXPECT_EQ(cv::sum(frame(cv::Rect(0, 440, 100, 40)))[0], 0);
}

TEST(Hud, TextPanelsDarkenWhatIsBehindThem) {
  const calib::Camera camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(200, 200, 200));
  DrawHud(frame, camera, LookingAlongZ(5), {}, {{"status"}, {"help line"}});
  EXPECT_LT(frame.at<cv::Vec3b>(12, 10)[0], 120);            // status box, top left
  EXPECT_LT(frame.at<cv::Vec3b>(frame.rows - 12, 10)[0], 120);  // help box, bottom left
  EXPECT_EQ(frame.at<cv::Vec3b>(240, 320)[0], 200);           // the rest untouched
}

}  // namespace
}  // namespace arview::render

namespace arview::render {
namespace {

TEST(Hud, EyeContactLineSaysWhereTheEyesAreAndABlink) {
  anim::GazeFrame eyes;
  EXPECT_EQ(EyeContactLine(eyes), "");  // a character without gaze
  eyes.active = true;
  EXPECT_EQ(EyeContactLine(eyes), "eyes away");
  eyes.eyes_on_viewer = true;
  EXPECT_EQ(EyeContactLine(eyes), "eye contact");
  eyes.blinking = true;
  EXPECT_EQ(EyeContactLine(eyes), "eye contact  (blink)");
}

}  // namespace
}  // namespace arview::render
