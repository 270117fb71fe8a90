#include "app/cli/session_flags.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace arview::app {
namespace {

// Parses `args` (without the program name) as `arview replay` would its session flags.
SessionOptions Parse(std::vector<std::string> args, bool live_source = false) {
  CLI::App cmd;
  SessionFlags flags;
  AddSessionFlags(&cmd, flags);
  args.insert(args.begin(), "replay");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  cmd.parse(static_cast<int>(argv.size()), argv.data());
  SessionOptions options;
  ApplySessionFlags(flags, live_source, options);
  return options;
}

TEST(SessionFlags, TrackerFlagsReachTheTrackerOptions) {
  const SessionOptions defaults = Parse({});
  EXPECT_EQ(defaults.tracker.tracking.prefetch_below, 0);
  EXPECT_EQ(defaults.tracker.tracking.align_max_seconds, tracker::TrackingOptions{}.align_max_seconds);
  const SessionOptions set = Parse({"--prefetch-below", "190", "--align-max-seconds", "0"});
  EXPECT_EQ(set.tracker.tracking.prefetch_below, 190);
  EXPECT_EQ(set.tracker.tracking.align_max_seconds, 0.0);
}

TEST(SessionFlags, TheTrackingWorkerIsOnForALiveSourceUnlessTurnedOff) {
  const SessionOptions recorded = Parse({});
  EXPECT_FALSE(recorded.tracker.tracking.background);
  const SessionOptions live = Parse({}, /*live_source=*/true);
  EXPECT_TRUE(live.tracker.tracking.background);
  EXPECT_EQ(live.tracker.tracking.prefetch_below, tracker::kBackgroundPrefetchBelow);
  const SessionOptions off = Parse({"--tracking-worker", "off"}, true);
  EXPECT_FALSE(off.tracker.tracking.background);
  EXPECT_EQ(off.tracker.tracking.prefetch_below, 0);
  const SessionOptions on = Parse({"--tracking-worker", "on", "--prefetch-below", "180"});
  EXPECT_TRUE(on.tracker.tracking.background);
  EXPECT_EQ(on.tracker.tracking.prefetch_below, 180);
  // With the worker, guided matching's features come only from extraction ahead.
  try {
    Parse({"--prefetch-below", "0"}, true);
    ADD_FAILURE() << "--prefetch-below 0 with the worker was taken";
  } catch (const OptionError& e) {  // TrackingOptions::Check, naming the flags
    EXPECT_STREQ(e.what(), "--prefetch-below 0 needs --tracking-worker off: with the worker, guided matching's SIFT "
                           "is extracted only ahead");
  }
  EXPECT_THROW(Parse({"--tracking-worker", "sometimes"}), CLI::ValidationError);
}

TEST(SessionFlags, TheDefaultsAreTheOptionsStructsOwn) {
  const SessionOptions defaults = Parse({});
  EXPECT_EQ(defaults.compositor.ipd_m, CompositorOptions{}.ipd_m);
  EXPECT_EQ(defaults.fade.hold_seconds, FadeOptions{}.hold_seconds);
  EXPECT_EQ(defaults.fade.fade_seconds, FadeOptions{}.fade_seconds);
}

// CompositorOptions::Check, naming the flags that set the fields.
TEST(SessionFlags, AStereoCharacterWithoutTheHmdIsRefusedNamingTheFlags) {
  try {
    Parse({"--stereo-character"});
    ADD_FAILURE() << "--stereo-character without --hmd was taken";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "--stereo-character needs --hmd or --hmd-profile");
  }
  EXPECT_TRUE(Parse({"--stereo-character", "--hmd"}).compositor.stereo_character);
}

TEST(SessionFlags, OutOfRangeTrackerFlagsAreRefused) {
  EXPECT_THROW(Parse({"--align-max-seconds", "-1"}), CLI::ValidationError);
  EXPECT_THROW(Parse({"--align-max-seconds", "11"}), CLI::ValidationError);
  EXPECT_THROW(Parse({"--prefetch-below", "-5"}), CLI::ValidationError);
}

}  // namespace
}  // namespace arview::app
