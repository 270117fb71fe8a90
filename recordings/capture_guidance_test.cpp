#include "recordings/capture_guidance.h"

#include <gtest/gtest.h>

#include <random>

#include <opencv2/imgproc.hpp>

namespace arview::recordings {
namespace {

// A texture of random blocks, blurred a little: corners everywhere.
cv::Mat Texture(cv::Size size, unsigned seed) {
  cv::Mat small(size.height / 8, size.width / 8, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(small, cv::RNG::UNIFORM, 30, 225);
  cv::Mat big;
  cv::resize(small, big, size, 0, 0, cv::INTER_NEAREST);
  cv::GaussianBlur(big, big, {3, 3}, 0.8);
  return big;
}

cv::Mat Crop(const cv::Mat& texture, cv::Point2d at, cv::Size size) {
  cv::Mat out;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -at.x, 0, 1, -at.y);
  cv::warpAffine(texture, out, shift, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

// A camera turning on the spot: the picture slides (a homography, as every rotation's is).
TEST(CaptureGuidance, ACameraTurningOnTheSpotHasNoParallax) {
  const cv::Mat world = Texture({1600, 480}, 1);
  CaptureGuidance guidance;
  for (int i = 0; i < 60; ++i) guidance.Add(Crop(world, {i * 3.0, 0}, {320, 240}), i / 15.0);
  const GuidanceSummary s = guidance.Summary();
  EXPECT_GE(s.steps, 3);
  EXPECT_EQ(s.steps_with_parallax, 0);
  ASSERT_FALSE(s.likely_to_map);
  EXPECT_NE(s.reasons.front().find("too little parallax"), std::string::npos) << s.Line();
  EXPECT_NE(guidance.Advice().find("too little parallax"), std::string::npos);
}

// Walking past things at two depths: the near layer slides twice as fast as the far one.
TEST(CaptureGuidance, WalkingPastThingsAtTwoDepthsHasParallaxAndIsLikelyToMap) {
  const cv::Mat far = Texture({1600, 480}, 2), near = Texture({3200, 480}, 3);
  CaptureGuidance guidance;
  std::vector<GuidanceNote> notes;
  for (int i = 0; i < 60; ++i) {
    cv::Mat frame = Crop(far, {i * 3.0, 0}, {320, 240});
    Crop(near, {i * 6.0, 0}, {320, 240})(cv::Rect(0, 120, 320, 120)).copyTo(frame(cv::Rect(0, 120, 320, 120)));
    guidance.Add(frame, i / 15.0);
    notes.insert(notes.end(), guidance.NewNotes().begin(), guidance.NewNotes().end());
  }
  const GuidanceSummary s = guidance.Summary();
  EXPECT_TRUE(s.likely_to_map) << s.Line();
  EXPECT_GE(s.steps_with_parallax, 3) << s.Line();
  EXPECT_TRUE(notes.empty()) << notes.front().text;
}

TEST(CaptureGuidance, ABlankWallHasTooFewFeatures) {
  cv::RNG rng(4);
  CaptureGuidance guidance;
  std::vector<GuidanceNote> notes;
  for (int i = 0; i < 30; ++i) {
    cv::Mat wall(480, 640, CV_8UC3, cv::Scalar(180, 185, 190)), noise(wall.size(), CV_8UC3);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2);
    wall += noise;
    guidance.Add(wall, i / 15.0);
    notes.insert(notes.end(), guidance.NewNotes().begin(), guidance.NewNotes().end());
  }
  const GuidanceSummary s = guidance.Summary();
  ASSERT_FALSE(s.likely_to_map);
  EXPECT_NE(s.reasons.front().find("too few features in 100% of the frames"), std::string::npos) << s.Line();
  ASSERT_EQ(notes.size(), 1u);  // said once, after a second of it
  EXPECT_NEAR(notes[0].time, 1.0, 0.07);
  EXPECT_NE(notes[0].text.find("too few features"), std::string::npos);
}

TEST(CaptureGuidance, APictureSmearedBySpeedIsTooFast) {
  const cv::Mat world = Texture({9600, 480}, 5);
  CaptureGuidance guidance;
  // 30 px a frame at 15 fps: 450 px/s, 7.5 px of smear in 1/60 s.
  for (int i = 0; i < 30; ++i) guidance.Add(Crop(world, {i * 30.0, 0}, {320, 240}), i / 15.0);
  EXPECT_NEAR(guidance.last().speed_px_s, 450, 10);
  EXPECT_TRUE(guidance.last().too_fast);
  const GuidanceSummary s = guidance.Summary();
  ASSERT_FALSE(s.likely_to_map);
  EXPECT_NE(s.Line().find("too fast in"), std::string::npos) << s.Line();
}

// The texture at a sixteenth of its light: its contrast falls below FAST's threshold.
TEST(CaptureGuidance, ADarkRoomIsTooDark) {
  CaptureGuidance guidance;
  cv::Mat dark = Texture({320, 240}, 6) / 16;
  for (int i = 0; i < 20; ++i) guidance.Add(dark, i / 15.0);
  EXPECT_TRUE(guidance.last().too_dark);
  EXPECT_NE(guidance.Advice().find("too dark"), std::string::npos);
  EXPECT_NE(guidance.Summary().Line().find("badly exposed"), std::string::npos);
}

// A lit, textured object on a black background (templeRing's turntable) is not badly exposed.
TEST(CaptureGuidance, ADarkBackgroundRoundATexturedObjectIsNotTooDark) {
  CaptureGuidance guidance;
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(0));
  Texture({80, 80}, 7).copyTo(frame(cv::Rect(120, 80, 80, 80)));
  for (int i = 0; i < 20; ++i) guidance.Add(frame, i / 15.0);
  EXPECT_LT(guidance.last().mean_grey, 40);
  EXPECT_FALSE(guidance.last().too_dark);
  EXPECT_EQ(guidance.Summary().badly_exposed, 0);
}

// At 30 fps every other frame is looked at.
TEST(CaptureGuidance, FramesSoonerThanTheRateAllowsAreSkipped) {
  const cv::Mat world = Texture({1600, 480}, 8);
  CaptureGuidance guidance;
  for (int i = 0; i < 30; ++i) guidance.Add(Crop(world, {i * 2.0, 0}, {320, 240}), i / 30.0);
  EXPECT_EQ(guidance.Summary().frames, 15);
  EXPECT_NEAR(guidance.last().speed_px_s, 60, 3);
}

TEST(CaptureGuidance, BadOptionsAreRefusedNamingTheField) {
  CaptureGuidanceOptions options;
  options.view_shift = 1.5;
  try {
    options.Check();
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("view_shift must be in (0, 1)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arview::recordings
