#include "tracker/moving_tracks.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <vector>

#include "tracker/brightness_match.h"
#include "tracker/hidden_points.h"

namespace arview::tracker {
namespace {

// 100 tracks on a grid, all off their prediction by a shared 2 px (the prediction's error) and
// a little noise; `moving` of them carried 5 px further by something moving.
struct Frame {
  std::vector<std::uint32_t> ids;
  std::vector<Eigen::Vector2d> pixels, predicted;
  std::vector<float> errors;
  FlowTracks View() const { return {ids, pixels, predicted, errors}; }
};
Frame MakeFrame(int moving, float moving_patch_error = 2.f) {
  Frame f;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector2d at(20.0 * (i % 10), 20.0 * (i / 10));
    const double noise = 0.2 * ((i * 7) % 5 - 2) / 2.0;
    f.ids.push_back(static_cast<std::uint32_t>(i));
    f.predicted.push_back(at);
    f.pixels.push_back(at + Eigen::Vector2d(2 + noise, -1) + (i < moving ? Eigen::Vector2d(5, 0) : Eigen::Vector2d::Zero()));
    f.errors.push_back(i < moving ? moving_patch_error : 2.f + 0.1f * static_cast<float>(i % 3));
  }
  return f;
}

TEST(MovingTracks, ATrackMovingAgainstThePredictionIsDroppedAfterTheStreakNotBefore) {
  MovingTrackFilter filter({}, 100);
  const Frame f = MakeFrame(5);
  const MovingTrackVerdict first = filter.Judge(f.View(), 1);
  EXPECT_EQ(first.by_motion, 0) << "one frame of disagreement is not yet a streak";
  const MovingTrackVerdict second = filter.Judge(f.View(), 2);
  EXPECT_EQ(second.by_motion, 5);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(second.keep[i], i >= 5) << i;
  EXPECT_EQ(second.rejected.size(), 5u);
}

TEST(MovingTracks, TheSharedErrorOfThePredictionRejectsNothing) {
  MovingTrackFilter filter({}, 100);
  const Frame f = MakeFrame(0);
  for (std::uint32_t frame = 1; frame < 5; ++frame) EXPECT_TRUE(filter.Judge(f.View(), frame).rejected.empty());
}

TEST(MovingTracks, AStreakBrokenByAFrameWithoutTheTrackStartsAgain) {
  MovingTrackFilter filter({}, 100);
  const Frame f = MakeFrame(5);
  EXPECT_EQ(filter.Judge(f.View(), 1).by_motion, 0);
  EXPECT_EQ(filter.Judge(f.View(), 3).by_motion, 0) << "frame 2 did not follow them";
}

TEST(MovingTracks, AChangedPatchIsDroppedAtOnceAndAGlobalLightChangeIsNot) {
  MovingTrackFilter filter({}, 100);
  const MovingTrackVerdict occluded = filter.Judge(MakeFrame(0).View(), 1);
  EXPECT_TRUE(occluded.rejected.empty());
  Frame covered = MakeFrame(0);
  covered.errors[42] = 40.f;  // something stepped over point 42
  const MovingTrackVerdict v = filter.Judge(covered.View(), 2);
  EXPECT_EQ(v.by_patch, 1);
  EXPECT_FALSE(v.keep[42]);
  Frame darker = MakeFrame(0);
  for (float& e : darker.errors) e *= 6;  // every patch changed alike
  EXPECT_TRUE(filter.Judge(darker.View(), 3).rejected.empty());
}

TEST(MovingTracks, ASharpCornerWhoseErrorIsAlwaysHighIsKeptAndItsJumpIsNot) {
  MovingTrackFilter filter({}, 100);
  Frame f = MakeFrame(0);
  f.errors[7] = 12.f;  // a high-contrast patch: 6 times the frame's median on every frame
  for (std::uint32_t frame = 1; frame < 4; ++frame) EXPECT_TRUE(filter.Judge(f.View(), frame).keep[7]) << frame;
  f.errors[7] = 60.f;  // then someone steps over it
  const MovingTrackVerdict v = filter.Judge(f.View(), 4);
  EXPECT_FALSE(v.keep[7]);
  EXPECT_EQ(v.by_patch, 1);
}

TEST(MovingTracks, ATrackFollowedForTheFirstTimeIsJudgedByItsMotionAlone) {
  MovingTrackFilter filter({}, 100);
  Frame f = MakeFrame(0);
  f.errors[3] = 40.f;
  EXPECT_TRUE(filter.Judge(f.View(), 1).keep[3]) << "no error of its own to compare with yet";
}

TEST(HiddenPoints, KeptUntilTooOldOrFoundAgain) {
  HiddenPoints hidden;
  hidden.Add({10, {}, {{1, 1}, {2, 2}}, {5, 6}});
  hidden.Add({12, {}, {{3, 3}}, {7}});
  hidden.Add({13, {}, {}, {}});  // nothing lost: not kept
  EXPECT_EQ(hidden.batches().size(), 2u);
  EXPECT_EQ(hidden.size(), 3u);
  hidden.Remove([](std::uint32_t id) { return id == 5; });
  ASSERT_EQ(hidden.size(), 2u);
  EXPECT_EQ(hidden.batches().front().point_ids, std::vector<std::uint32_t>{6});
  EXPECT_EQ(hidden.batches().front().pixels.front(), cv::Point2f(2, 2)) << "pixels stay with their points";
  hidden.Expire(70, 60);  // frame 10 is 60 frames before: kept
  EXPECT_EQ(hidden.size(), 2u);
  hidden.Expire(71, 60);
  EXPECT_EQ(hidden.size(), 1u);
  hidden.Remove([](std::uint32_t id) { return id == 7; });
  EXPECT_TRUE(hidden.batches().empty()) << "an emptied batch is dropped";
}

TEST(MovingTracks, GuidedMatchesNearARejectedTrackAreTheMoversRegion) {
  MovingTrackVerdict verdict;
  verdict.rejected = {{100, 100}};
  EXPECT_TRUE(MovingTrackFilter::NearRejected(verdict, {110, 105}, 16));
  EXPECT_FALSE(MovingTrackFilter::NearRejected(verdict, {130, 100}, 16));
}

TEST(MovingTracks, DisabledKeepsEverything) {
  MovingTrackOptions options;
  options.enabled = false;
  MovingTrackFilter filter(options, 100);
  const Frame f = MakeFrame(20, 50.f);
  filter.Judge(f.View(), 1);
  EXPECT_TRUE(filter.Judge(f.View(), 2).rejected.empty());
}

TEST(MovingTracks, BadOptionsNameTheirField) {
  MovingTrackOptions options;
  options.patch_error_ratio = 0.5;
  try {
    options.Check();
    FAIL() << "a ratio below 1 must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("patch_error_ratio"), std::string::npos) << e.what();
  }
}

TEST(BrightnessMatch, AFrameTwoStopsDarkerIsScaledToTheReferenceAndAnOrdinaryOneIsLeftAlone) {
  cv::Mat reference(48, 64, CV_8U), dark, slightly;
  cv::randu(reference, 40, 200);
  reference.convertTo(dark, CV_8U, 0.25);
  const BrightnessMatch matched = MatchMeanBrightness(dark, reference, 0.05);
  EXPECT_NEAR(cv::mean(matched.image)[0], cv::mean(reference)[0], 1.0);
  EXPECT_TRUE(matched.light_changed());
  EXPECT_NEAR(matched.gain, 4.0, 0.1);
  reference.convertTo(slightly, CV_8U, 0.98);
  const BrightnessMatch ordinary = MatchMeanBrightness(slightly, reference, 0.05);
  EXPECT_EQ(ordinary.image.data, slightly.data) << "within the tolerance: the frame itself";
  EXPECT_FALSE(ordinary.light_changed());
  const cv::Mat black = cv::Mat::zeros(48, 64, CV_8U);
  EXPECT_EQ(MatchMeanBrightness(black, reference, 0.05).image.data, black.data);
}

}  // namespace
}  // namespace arview::tracker
