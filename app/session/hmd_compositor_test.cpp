// The compositor's headset output (issue 35, "a headset mode that is honest"): the two eyes get
// the same video, and the character biocular (identical halves) unless --stereo-character, which
// gives it disparity while the video stays the same in both eyes; with a profile, the panel is
// the profile's size.

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "anim_authoring/character_builder.h"
#include "app/pipeline/ar_compositor.h"
#include "app/session/character_setup.h"
#include "tests/support/fox_view.h"
#include "tests/support/test_data.h"

namespace arview::app {
namespace {

authoring::CharacterSpec FoxSpec() {
  return authoring::ParseScene(arview::testing::FoxSceneYaml(), "fox-hmd-test.yaml").characters.at(0);
}

using arview::testing::LookingAtFox;

class HmdCompositor : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(arview::testing::SharedData("characters/Fox"), "../shared/data");
    fox_ = std::make_unique<authoring::AnimatedCharacter>(FoxSpec());
    animator_ = MakeLayeredAnimator(*fox_, "", {0.5, 1.0});
    frame_.image = cv::Mat(camera_.Size(), CV_8UC3);
    cv::randu(frame_.image, 0, 255);  // a video whose every pixel tells the eyes apart
    track_.status = tracker::TrackStatus::kTracking;
    track_.pose = LookingAtFox();
    track_.center = track_.smoothed_center = track_.pose.Center();
  }
  cv::Mat Compose(const CompositorOptions& options) {
    ArCompositor compositor(camera_, {fox_.get()}, options);
    compositor.BindToThread();
    FrameToCompose input{&frame_, &track_, {&animator_->Update(track_.center, 0.0)}};
    return compositor.Compose(input);
  }
  const calib::Camera camera_ = calib::Camera::Pinhole(640, 480, 600, 590, 322.5, 236.0);
  std::unique_ptr<authoring::AnimatedCharacter> fox_;
  std::unique_ptr<LayeredAnimator> animator_;
  recordings::Frame frame_;
  tracker::FrameResult track_;
};

TEST_F(HmdCompositor, BothEyesSeeTheSameVideoAndTheCharacterBiocularByDefault) {
  CompositorOptions o;
  o.hmd = true;
  const cv::Mat both = Compose(o);
  ASSERT_EQ(both.size(), cv::Size(1280, 480));
  const cv::Mat left = both(cv::Rect(0, 0, 640, 480)), right = both(cv::Rect(640, 0, 640, 480));
  EXPECT_EQ(cv::norm(left, right, cv::NORM_INF), 0) << "biocular: the halves are the same picture";
  cv::Mat changed;
  cv::absdiff(left, frame_.image, changed);
  cv::cvtColor(changed, changed, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(changed > 40), 3000) << "the character is drawn";
}

TEST_F(HmdCompositor, StereoCharacterHasDisparityOverTheSameVideo) {
  CompositorOptions o;
  o.hmd = true;
  o.stereo_character = true;
  const cv::Mat both = Compose(o);
  const cv::Mat left = both(cv::Rect(0, 0, 640, 480)), right = both(cv::Rect(640, 0, 640, 480));
  cv::Mat left_drawn, right_drawn;
  cv::absdiff(left, frame_.image, left_drawn);
  cv::absdiff(right, frame_.image, right_drawn);
  cv::cvtColor(left_drawn, left_drawn, cv::COLOR_BGR2GRAY);
  cv::cvtColor(right_drawn, right_drawn, cv::COLOR_BGR2GRAY);
  const cv::Mat in_left = left_drawn > 40, in_right = right_drawn > 40;
  const cv::Moments l = cv::moments(in_left, true), r = cv::moments(in_right, true);
  ASSERT_GT(l.m00, 1000);
  ASSERT_GT(r.m00, 1000);
  const double disparity = l.m10 / l.m00 - r.m10 / r.m00;
  std::printf("[hmd] stereo character: disparity %.1f px\n", disparity);
  EXPECT_GT(disparity, 10);
  // Where neither eye drew anything (the character, its antialiased rim, its shadow), both show
  // the video unchanged.
  cv::Mat neither = ~((left_drawn > 0) | (right_drawn > 0));
  cv::erode(neither, neither, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
  cv::Mat video_left, video_right;
  left.copyTo(video_left, neither);
  right.copyTo(video_right, neither);
  EXPECT_GT(cv::countNonZero(neither), 200000);
  EXPECT_EQ(cv::norm(video_left, video_right, cv::NORM_INF), 0);
}

TEST_F(HmdCompositor, AProfileGivesThePanelAndTheLensedHalves) {
  CompositorOptions o;
  o.hmd = true;
  render::HmdProfile p;
  p.name = "test";
  p.panel = {1600, 900};
  p.eye_fov_deg = 80;
  p.k1 = 0.3, p.k2 = 0.2;
  o.hmd_profile = p;
  o.hud = true;  // drawn into the eye's view before the pre-distortion
  const cv::Mat panel = Compose(o);
  ASSERT_EQ(panel.size(), cv::Size(1600, 900));
  EXPECT_EQ(cv::norm(panel(cv::Rect(0, 0, 800, 900)), panel(cv::Rect(800, 0, 800, 900)), cv::NORM_INF), 0);
  EXPECT_EQ(panel.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0)) << "the corner is outside the lens's view";
}

}  // namespace
}  // namespace arview::app
