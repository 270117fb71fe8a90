// Each options struct of the tracker refuses a bad value with one line naming the field (by its
// path, or by the name the caller gives it: arview track's flags) and what it must be.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "tracker/tracker.h"

namespace arview::tracker {
namespace {

// The OptionError `check` throws: its message.
std::string Refusal(const std::function<void()>& check) {
  try {
    check();
  } catch (const OptionError& e) {
    return e.what();
  }
  return "(nothing refused)";
}

TEST(TrackerOptionsCheck, TheDefaultsPass) {
  EXPECT_NO_THROW(TrackerOptions{}.Check());
  EXPECT_NO_THROW(RelocalizerOptions{}.Check());
  EXPECT_NO_THROW(TrackingOptions{}.Check());
  EXPECT_NO_THROW(AbsolutePoseOptions{}.Check());
  EXPECT_NO_THROW(FeatureOptions{}.Check());
  EXPECT_NO_THROW(MatchOptions{}.Check());
  EXPECT_NO_THROW(OneEuroOptions{}.Check());
}

TEST(TrackerOptionsCheck, FeatureOptionsNameTheBadField) {
  FeatureOptions o;
  o.contrast_threshold = 0;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "contrast_threshold must be above 0 (got 0)");
  o = {};
  o.max_features = -1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "max_features must be 0 (all) or more (got -1)");
}

TEST(TrackerOptionsCheck, MatchOptionsNameTheBadField) {
  MatchOptions o;
  o.ratio = 1.5;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "ratio must be in (0, 1] (got 1.5)");
  o.ratio = std::nan("");
  EXPECT_EQ(Refusal([&] { o.Check(); }), "ratio must be in (0, 1] (got nan)");
  o = {};
  o.knn = 1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "knn must be at least 2 (got 1)");
}

TEST(TrackerOptionsCheck, AbsolutePoseOptionsNameTheBadField) {
  AbsolutePoseOptions o;
  o.min_inliers = 2;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "min_inliers must be at least 3 (got 2)");
  o = {};
  o.ransac_success_probability = 1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "ransac_success_probability must be in (0, 1) (got 1)");
}

// Which image SIFT sees, and with which settings, by the working frame's size: still photos up to
// sift_own_size_up_to at their own size with `features` (Herz-Jesus-P25's 768x512), longer frames
// reduced to sift_long_side with `reduced_features` and relocalised at reloc_sift_long_side.
TEST(SiftImage, FramesUpToTheOwnSizeKeepItAndTheOwnSizeSettings) {
  const RelocalizerOptions o;
  const calib::Camera photo = calib::Camera::Pinhole(768, 512, 690, 691, 380, 251);
  EXPECT_EQ(SiftLongSide(photo, o), 0);
  EXPECT_EQ(RelocSiftLongSide(photo, o), 0);
  EXPECT_EQ(&ActiveFeatures(photo, o), &o.features);
  const calib::Camera vga = calib::Camera::Pinhole(640, 480, 500, 500, 320, 240);
  EXPECT_EQ(SiftLongSide(vga, o), 0);
  EXPECT_EQ(&ActiveFeatures(vga, o), &o.features);
  const calib::Camera phone_working = calib::Camera::Pinhole(540, 960, 688, 687, 277, 482);
  EXPECT_EQ(SiftLongSide(phone_working, o), 640);
  EXPECT_EQ(RelocSiftLongSide(phone_working, o), 480);
  EXPECT_EQ(&ActiveFeatures(phone_working, o), &o.reduced_features);

  RelocalizerOptions reduce_photos;
  reduce_photos.sift_own_size_up_to = 0;  // the rule before: every frame over sift_long_side reduced
  EXPECT_EQ(SiftLongSide(photo, reduce_photos), 640);
  EXPECT_EQ(RelocSiftLongSide(photo, reduce_photos), 480);
  EXPECT_EQ(&ActiveFeatures(photo, reduce_photos), &reduce_photos.reduced_features);
}

TEST(TrackerOptionsCheck, RelocalizerOptionsNameTheBadFieldAndItsMembers) {
  RelocalizerOptions o;
  o.sift_long_side = 32;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "sift_long_side must be 0 (the working resolution) or at least 64 (got 32)");
  o = {};
  o.reloc_sift_long_side = 10;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "reloc_sift_long_side must be 0 (as sift_long_side) or at least 64 (got 10)");
  o = {};
  o.sift_own_size_up_to = -1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "sift_own_size_up_to must be 0 or more (got -1)");
  o = {};
  o.pose.inlier_threshold_px = -1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "pose.inlier_threshold_px must be above 0 (got -1)");
  o = {};
  o.reduced_features.sigma = 0;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "reduced_features.sigma must be above 0 (got 0)");
}

TEST(TrackerOptionsCheck, OneEuroOptionsNameTheBadField) {
  OneEuroOptions o;
  o.beta = -0.5;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "beta must be 0 or more (got -0.5)");
}

TEST(TrackerOptionsCheck, TrackingOptionsNameTheBadField) {
  TrackingOptions o;
  o.lk_window_px = 1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "lk_window_px must be at least 3 (got 1)");
  o = {};
  o.fresh_features_after_s = std::nan("");
  EXPECT_EQ(Refusal([&] { o.Check(); }), "fresh_features_after_s must be a number (negative: never) (got nan)");
  o = {};
  o.fresh_features_after_s = -0.5;  // negative: never, as documented
  EXPECT_NO_THROW(o.Check());
  // With the worker, guided matching's SIFT comes only from extraction ahead.
  o = {};
  o.background = true;
  o.prefetch_below = 0;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "prefetch_below 0 needs background off: with the worker, guided matching's "
                                         "SIFT is extracted only ahead");
  o.prefetch_below = kBackgroundPrefetchBelow;
  EXPECT_NO_THROW(o.Check());
}

TEST(TrackerOptionsCheck, TrackerOptionsNameTheFieldByItsPathThroughEveryMember) {
  TrackerOptions o;
  o.working_long_side = 63;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "working_long_side must be 0 (full resolution) or at least 64 (got 63)");
  o = {};
  o.working_long_side = 0;
  EXPECT_NO_THROW(o.Check());
  o.relocalization.matching.ratio = 0;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "relocalization.matching.ratio must be in (0, 1] (got 0)");
  o = {};
  o.relocalization.keyframe_matching = -1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "relocalization.keyframe_matching must be 0 or more (got -1)");
  o = {};
  o.relocalization.keyframe_knn = 1;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "relocalization.keyframe_knn must be at least 2 (got 1)");
  o = {};
  o.tracking.guided_ratio = 2;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "tracking.guided_ratio must be in (0, 1] (got 2)");
  o = {};
  o.smoothing.min_cutoff_hz = 0;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "smoothing.min_cutoff_hz must be above 0 (got 0)");
  o = {};
  o.index.checks = 0;
  EXPECT_EQ(Refusal([&] { o.Check(); }), "index.checks must be at least 1 (got 0)");
}

// arview track names the fields by its flags: the user reads the flag they gave.
TEST(TrackerOptionsCheck, TheCallersNamesReplaceTheFieldsPaths) {
  const OptionNames flags({{"working_long_side", "--working-size"},
                           {"relocalization.sift_long_side", "--sift-size"},
                           {"relocalization.reloc_sift_long_side", "--reloc-sift-size"}});
  TrackerOptions o;
  o.relocalization.reloc_sift_long_side = 10;
  EXPECT_EQ(Refusal([&] { o.Check(flags); }), "--reloc-sift-size must be 0 (as --sift-size) or at least 64 (got 10)");
}

// The tracker checks its options before it reads the map: an empty map is not even looked at.
TEST(TrackerOptionsCheck, TheTrackerRefusesBadOptionsNamingThemAsTrackerFields) {
  const map::Map no_map;
  TrackerOptions o;
  o.relocalization.sift_long_side = 10;
  EXPECT_EQ(Refusal([&] { Tracker tracker(no_map, o); }),
            "tracker.relocalization.sift_long_side must be 0 (the working resolution) or at least 64 (got 10)");
}

}  // namespace
}  // namespace arview::tracker
