#include "tracker/research_trigger.h"

#include <gtest/gtest.h>

#include <vector>

#include "base/error.h"

namespace arview::tracker {
namespace {

const cv::Size kImage(640, 480);

// `n` tracks spread over the whole 640x480 image (every quadrant), or only its left half.
std::vector<Eigen::Vector2d> Tracks(int n, bool left_half_only = false) {
  std::vector<Eigen::Vector2d> tracks;
  for (int i = 0; i < n; ++i) {
    tracks.emplace_back(10.0 + (i * 137) % (left_half_only ? 300 : 620), 10.0 + (i * 89) % 460);
  }
  return tracks;
}

ResearchTriggerOptions WithCredit(int frames) {
  ResearchTriggerOptions o;
  o.occlusion_credit_frames = frames;
  return o;
}

TEST(ResearchTrigger, WithoutCreditItIsAPlainCountUnderReplenishBelow) {
  ResearchTrigger trigger({}, 150);
  trigger.Occluded(1, 100);  // ignored: no credit
  EXPECT_FALSE(trigger.Due(2, Tracks(150), kImage));
  EXPECT_TRUE(trigger.Due(2, Tracks(149), kImage));
  EXPECT_EQ(trigger.Credit(2), 0);
}

TEST(ResearchTrigger, TracksThePatchTestDroppedCountAsExpectedBackUntilTheCreditRunsOut) {
  ResearchTrigger trigger(WithCredit(30), 150);
  trigger.Occluded(10, 40);
  trigger.Occluded(12, 20);
  EXPECT_EQ(trigger.Credit(12), 60);
  EXPECT_FALSE(trigger.Due(12, Tracks(100), kImage)) << "100 followed + 60 expected back";
  EXPECT_TRUE(trigger.Due(12, Tracks(80), kImage)) << "80 + 60 is under 150";
  EXPECT_EQ(trigger.Credit(40), 20) << "frame 10's drops are 30 frames old at frame 40";
  EXPECT_TRUE(trigger.Due(40, Tracks(100), kImage));
  EXPECT_EQ(trigger.Credit(42), 0);
}

TEST(ResearchTrigger, AReSearchClearsTheCredit) {
  ResearchTrigger trigger(WithCredit(30), 150);
  trigger.Occluded(5, 80);
  EXPECT_FALSE(trigger.Due(6, Tracks(100), kImage));
  trigger.Searched(6);
  EXPECT_TRUE(trigger.Due(6, Tracks(100), kImage));
}

TEST(ResearchTrigger, EveryMaxFramesBetweenAFrameReSearchesWhateverItsCount) {
  ResearchTriggerOptions o;
  o.max_frames_between = 45;
  ResearchTrigger trigger(o, 150);
  EXPECT_FALSE(trigger.Due(100, Tracks(300), kImage)) << "no re-search yet to count from";
  trigger.Searched(10);
  EXPECT_FALSE(trigger.Due(54, Tracks(300), kImage));
  EXPECT_FALSE(trigger.AgeDue(54));
  EXPECT_TRUE(trigger.Due(55, Tracks(300), kImage));
  EXPECT_TRUE(trigger.AgeDue(55)) << "what a live session extracts SIFT ahead for";
  trigger.Searched(55);
  EXPECT_FALSE(trigger.Due(56, Tracks(300), kImage));
  trigger.Clear();
  EXPECT_FALSE(trigger.Due(200, Tracks(300), kImage)) << "a lost prior forgets the last re-search";
}

TEST(ResearchTrigger, ByDefaultEveryTenthFrameReSearchesAndZeroNever) {
  ResearchTrigger trigger({}, 150);
  trigger.Searched(0);
  EXPECT_FALSE(trigger.Due(9, Tracks(300), kImage));
  EXPECT_TRUE(trigger.Due(10, Tracks(300), kImage));
  ResearchTriggerOptions never;
  never.max_frames_between = 0;
  ResearchTrigger off(never, 150);
  off.Searched(0);
  EXPECT_FALSE(off.Due(1000, Tracks(300), kImage));
  EXPECT_FALSE(off.AgeDue(1000));
}

TEST(ResearchTrigger, TooFewTracksFollowedOrAllOnOneSideReSearchWhateverTheCredit) {
  ResearchTrigger trigger(WithCredit(30), 150);
  trigger.Occluded(1, 1000);
  EXPECT_TRUE(trigger.Due(2, Tracks(74), kImage)) << "under half of replenish_below really followed";
  EXPECT_FALSE(trigger.Due(2, Tracks(75), kImage));
  EXPECT_TRUE(trigger.Due(2, Tracks(120, true), kImage)) << "two quadrants only: the pose is not pinned";
}

TEST(ResearchTrigger, OptionsCheckThemselves) {
  ResearchTriggerOptions o;
  o.min_quadrants = 5;
  EXPECT_THROW(o.Check(), OptionError);
  o = {};
  o.occlusion_credit_frames = -1;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_NO_THROW(ResearchTriggerOptions{}.Check());
}

}  // namespace
}  // namespace arview::tracker
