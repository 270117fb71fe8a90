#include "tracker/tracker.h"
#include "tracker/tracker_internal.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <thread>

#include "tests/support/sanitizer_slowdown.h"
#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"
#include "tracker/test_scene.h"

namespace arview::tracker {
namespace {

using testing::LookAt;
using testing::PlanarWorld;
using testing::RotationErrorDeg;
using testing::TestCamera;

const char* kOpenCvData = "/usr/share/doc/opencv-doc/examples/data/";

// A graffiti texture on a 1.2 m x 0.96 m plane, mapped from four keyframes ~0.9 m away.
class PlanarTrackerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const cv::Mat texture = cv::imread(std::string(kOpenCvData) + "graf1.png");
    if (texture.empty()) return;
    world_ = std::make_unique<PlanarWorld>(texture, TestCamera(), 0.0015);
    const SiftExtractor sift;
    map_ = std::make_unique<map::Map>(world_->MakeMap(testing::GraffitiKeyframes(), sift));
  }
  static void TearDownTestSuite() {
    map_.reset();
    world_.reset();
  }
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(std::string(kOpenCvData) + "graf1.png", "Debian package opencv-doc");
    ASSERT_TRUE(map_);
  }

  static calib::Pose PathPose(int i) {  // a slow sideways arc, ~4 mm per frame
    const double a = 0.004 * i;
    return LookAt({-0.15 + a, 0.05 * std::sin(3 * a), -0.8 - 0.1 * a}, {0.02, 0, 0});
  }

  static void ExpectNear(const FrameResult& r, const calib::Pose& truth, double metres, double deg) {
    EXPECT_LT((r.pose.Center() - truth.Center()).norm(), metres);
    EXPECT_LT(RotationErrorDeg(r.pose, truth), deg);
  }

  static std::unique_ptr<PlanarWorld> world_;
  static std::unique_ptr<map::Map> map_;
};
std::unique_ptr<PlanarWorld> PlanarTrackerTest::world_;
std::unique_ptr<map::Map> PlanarTrackerTest::map_;

TEST_F(PlanarTrackerTest, RelocalizesANovelView) {
  Tracker tracker(*map_);
  const calib::Pose truth = LookAt({0.12, 0.06, -0.75}, {0.03, 0.01, 0});
  const FrameResult r = tracker.Track(world_->Render(truth), 0.0);
  ASSERT_EQ(r.status, TrackStatus::kRelocalized) << r.reason;
  ExpectNear(r, truth, 0.003, 0.2);
  EXPECT_GE(r.inliers, 50);
  EXPECT_LT(r.rms_px, 1.0);
  EXPECT_GT(r.keypoints, 0);
  EXPECT_GT(r.matches, r.inliers / 2);
}

// The plane seen by a distorted 1280x720 camera, mapped from three views; nullptr without the
// texture. Built once for the tests below.
struct HdPlane {
  PlanarWorld world;
  map::Map map;
};
const HdPlane* HdPlaneScene() {
  static const std::unique_ptr<HdPlane> scene = []() -> std::unique_ptr<HdPlane> {
    const cv::Mat texture = cv::imread(std::string(kOpenCvData) + "graf1.png");
    if (texture.empty()) return nullptr;
    calib::Camera camera = calib::Camera::Pinhole(1280, 720, 1040, 1036, 645.5, 362);
    camera.dist = TestCamera().dist;
    PlanarWorld world(texture, camera, 0.0015);
    map::Map map = world.MakeMap({LookAt({0, 0, -0.9}, {0, 0, 0}), LookAt({0.3, 0, -0.85}, {0.05, 0, 0}),
                                  LookAt({-0.3, 0.1, -0.85}, {-0.05, 0, 0})},
                                 SiftExtractor());
    return std::make_unique<HdPlane>(HdPlane{std::move(world), std::move(map)});
  }();
  return scene.get();
}

// A 1280x720 camera (the tracker works at 960x540): relocalization's SIFT on the frame reduced
// to 480x270 (the default reloc_sift_long_side, as --sift-size 640 reduces this frame) finds the
// pose as accurately as on the working image (its keypoints mapped back to working pixels; used
// as found they would miss the pose; the mapping's exactness is WorkingResolution's tests).
TEST(PlanarTrackerAtHd, RelocalizesWithSiftOnAReducedImage) {
  const HdPlane* hd = HdPlaneScene();
  if (!hd) GTEST_SKIP() << "graf1.png missing (Debian package opencv-doc)";
  const PlanarWorld& world = hd->world;
  const map::Map& map = hd->map;
  const calib::Pose truth = LookAt({0.12, 0.06, -0.75}, {0.03, 0.01, 0});
  const cv::Mat frame = world.Render(truth);
  for (int reloc_side : {640, 0}) {
    TrackerOptions options;
    options.relocalization.sift_long_side = reloc_side;
    Tracker tracker(map, options);
    const FrameResult r = tracker.Track(frame, 0.0);
    ASSERT_EQ(r.status, TrackStatus::kRelocalized) << "reloc size " << reloc_side << ": " << r.reason;
    EXPECT_LT((r.pose.Center() - truth.Center()).norm(), 0.003) << "reloc size " << reloc_side;
    EXPECT_LT(RotationErrorDeg(r.pose, truth), 0.2) << "reloc size " << reloc_side;
    EXPECT_LT(r.rms_px, 1.0) << "reloc size " << reloc_side;
    EXPECT_GE(r.inliers, 50) << "reloc size " << reloc_side;
  }
}

// On a reduced frame that the flow lost (a jump: fewer tracks than a pose needs), the frame's SIFT is relocalization's own (the
// smaller image, its settings), so that the fallback costs one extraction of relocalization's size
// (phone-fox: 180 -> 84 ms on such a frame). Its keypoints are those a fresh tracker's
// relocalization of the same frame finds, and the pose is as exact.
TEST(PlanarTrackerAtHd, AJumpOnAReducedFrameCostsOneRelocalizationExtraction) {
  const HdPlane* hd = HdPlaneScene();
  if (!hd) GTEST_SKIP() << "graf1.png missing (Debian package opencv-doc)";
  const PlanarWorld& world = hd->world;
  const map::Map& map = hd->map;
  const calib::Pose start = LookAt({0.12, 0.06, -0.75}, {0.03, 0.01, 0});
  const calib::Pose far = LookAt({-0.1, -0.05, -0.8}, {-0.02, 0.02, 0}, Eigen::Vector3d::UnitY());  // upside down
  const cv::Mat far_frame = world.Render(far);
  Tracker fresh(map);
  const FrameResult own = fresh.Track(far_frame, 0.0);
  ASSERT_EQ(own.status, TrackStatus::kRelocalized) << own.reason;
  ASSERT_GT(own.keypoints, 0);

  TrackerOptions options;
  // LK follows ~180 of the start's tracks to wrong places on this texture (phone-fox's blurred
  // frame 18 kept 2): they are fewer than a pose needs, with guided matching due, when both
  // thresholds are above that.
  options.tracking.min_inliers = 400;
  options.tracking.replenish_below = 400;
  Tracker tracker(map, options);
  ASSERT_EQ(tracker.Track(world.Render(start), 0.0).status, TrackStatus::kRelocalized);
  const FrameResult jump = tracker.Track(far_frame, 1 / 30.0);
  ASSERT_NE(jump.status, TrackStatus::kLost) << jump.reason;
  ASSERT_LT(jump.flow_tracks, options.tracking.min_inliers);
  EXPECT_EQ(jump.keypoints, own.keypoints);
  EXPECT_LT((jump.pose.Center() - far.Center()).norm(), 0.003);
  EXPECT_LT(RotationErrorDeg(jump.pose, far), 0.2);
}

// Fresh features (fresh_features_after_s) on a reduced frame the flow posed alone: the fresh pose comes from
// relocalization's own extraction (a smaller image), the keypoints a fresh tracker's
// relocalization of the same frame finds, and it is as exact.
TEST(PlanarTrackerAtHd, FreshFeaturesOfAFlowFrameAreRelocalizationsOwn) {
  const HdPlane* hd = HdPlaneScene();
  if (!hd) GTEST_SKIP() << "graf1.png missing (Debian package opencv-doc)";
  const PlanarWorld& world = hd->world;
  const map::Map& map = hd->map;
  const calib::Pose start = LookAt({0.12, 0.06, -0.75}, {0.03, 0.01, 0});
  const calib::Pose next = LookAt({0.125, 0.06, -0.75}, {0.03, 0.01, 0});  // 5 mm aside
  const cv::Mat next_frame = world.Render(next);
  Tracker own(map);
  const FrameResult relocalised = own.Track(next_frame, 0.0);
  ASSERT_EQ(relocalised.status, TrackStatus::kRelocalized) << relocalised.reason;

  TrackerOptions options;
  options.tracking.fresh_features_after_s = 0;  // every tracked frame
  options.tracking.replenish_below = 0;  // the flow alone: no guided SIFT to reuse
  Tracker tracker(map, options);
  ASSERT_EQ(tracker.Track(world.Render(start), 0.0).status, TrackStatus::kRelocalized);
  const FrameResult r = tracker.Track(next_frame, 1 / 30.0);
  ASSERT_EQ(r.status, TrackStatus::kTracking) << r.reason;
  EXPECT_EQ(r.guided_matches, 0);
  EXPECT_GT(r.fresh_inliers, 0);
  EXPECT_EQ(r.keypoints, relocalised.keypoints);
  EXPECT_LT((r.pose.Center() - next.Center()).norm(), 0.003);
  EXPECT_LT(RotationErrorDeg(r.pose, next), 0.2);
}

// Relocalization's own SIFT size: smaller only for frames that --sift-size reduces anyway.
TEST(RelocSiftLongSide, ReducesOnlyFramesThatSiftReduces) {
  const calib::Camera vga = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  const calib::Camera working_hd = calib::Camera::Pinhole(540, 960, 800, 800, 269.5, 479.5);  // portrait
  const RelocalizerOptions defaults;
  ASSERT_EQ(defaults.sift_long_side, 640);
  ASSERT_EQ(defaults.reloc_sift_long_side, 480);
  // Up to sift_own_size_up_to (768) SIFT takes the frame as it is (0): not reduced.
  EXPECT_EQ(RelocSiftLongSide(vga, defaults), 0);
  const calib::Camera photo = calib::Camera::Pinhole(768, 512, 700, 700, 383.5, 255.5);  // Herz-Jesus' size
  EXPECT_EQ(RelocSiftLongSide(photo, defaults), 0);
  RelocalizerOptions no_own_size = defaults;
  no_own_size.sift_own_size_up_to = 0;
  EXPECT_EQ(RelocSiftLongSide(vga, no_own_size), 640);    // as SIFT sees it: not reduced either
  EXPECT_EQ(RelocSiftLongSide(photo, no_own_size), 480);  // reduced to 640 by SIFT, 480 here
  EXPECT_EQ(RelocSiftLongSide(working_hd, defaults), 480);  // SIFT reduces it: further still
  RelocalizerOptions same_as_sift = defaults;
  same_as_sift.reloc_sift_long_side = 0;
  EXPECT_EQ(RelocSiftLongSide(working_hd, same_as_sift), 640);
  RelocalizerOptions working_resolution = defaults;
  working_resolution.sift_long_side = 0;  // SIFT on the working frame: relocalization too
  EXPECT_EQ(RelocSiftLongSide(working_hd, working_resolution), 0);
}

TEST_F(PlanarTrackerTest, TracksASequenceThenRelocalizesAfterAJump) {
  Tracker tracker(*map_);
  int tracked = 0;
  for (int i = 0; i < 30; ++i) {
    const calib::Pose truth = PathPose(i);
    const FrameResult r = tracker.Track(world_->Render(truth), i / 30.0);
    ASSERT_NE(r.status, TrackStatus::kLost) << "frame " << i << ": " << r.reason;
    ExpectNear(r, truth, 0.003, 0.2);
    if (i == 0) {
      EXPECT_EQ(r.status, TrackStatus::kRelocalized);
    }
    if (r.status == TrackStatus::kTracking) {
      ++tracked;
      EXPECT_EQ(r.matches, 0) << "tracking must not run global matching";
    }
  }
  EXPECT_GE(tracked, 28);
  // A jump to the other side, the camera rolled by 90°: the constant-velocity prior is wrong
  // and optical flow cannot follow, relocalization recovers.
  const calib::Pose far = LookAt({0.25, -0.15, -0.7}, {-0.05, 0.05, 0}, Eigen::Vector3d::UnitX());
  const FrameResult r = tracker.Track(world_->Render(far), 1.0);
  ASSERT_EQ(r.status, TrackStatus::kRelocalized)
      << r.reason << " flow " << r.flow_tracks << " guided " << r.guided_matches << " inliers "
      << r.inliers << " err " << (r.pose.Center() - far.Center()).norm();
  ExpectNear(r, far, 0.003, 0.2);
}

// A light switched (a brightness step of light_switch_ev or more: the lamp's -2 EV) holds the
// tracked pose to the RMS gate's upper bound for light_switch_hold_s, where an auto-exposure
// stepping back on clipped frames fit above the gate learnt on steady ones (the lamp's nine
// relocalizations; docs/tracker.md, "Third round"); then the learnt gate is back. A smaller step
// (an exposure's 1/3 EV) opens the gate on its own frame only.
TEST_F(PlanarTrackerTest, ALightSwitchOpensTheRmsGateForTheHoldAnExposureStepForItsFrame) {
  TrackerOptions options;
  options.tracking.light_switch_hold_s = 0.5;  // off by default; a switch from 0.5 EV
  Tracker tracker(*map_, options);
  const double upper = options.tracking.rms_gate.max_px;
  const int lamp_off = 10, exposure_step = 35;  // frames
  for (int i = 0; i < 40; ++i) {
    const double gain = i < lamp_off ? 1.0 : i < exposure_step ? 0.25 : 0.25 * std::pow(2.0, 1.0 / 3);
    cv::Mat frame;
    world_->Render(PathPose(i)).convertTo(frame, -1, gain);
    const FrameResult r = tracker.Track(frame, i / 30.0);
    ASSERT_EQ(r.status, i == 0 ? TrackStatus::kRelocalized : TrackStatus::kTracking) << "frame " << i << ": " << r.reason;
    ExpectNear(r, PathPose(i), 0.003, 0.2);
    if (i == 0 || i == lamp_off + 15) continue;  // 0.5 s after the switch, up to rounding
    const bool held = (i >= lamp_off && i < lamp_off + 15) || i == exposure_step;
    if (held) {
      EXPECT_EQ(r.rms_gate_px, upper) << "frame " << i;
    } else {
      EXPECT_LT(r.rms_gate_px, upper) << "frame " << i;
    }
  }
}

// A venue's map (map::Map::rooms): a localized frame names its nearest keyframe's room, and the
// name changes when the camera moves over to the other room's keyframes; a lost frame and a map
// without rooms name none.
TEST_F(PlanarTrackerTest, ALocalizedFrameNamesTheRoomOfItsNearestKeyframe) {
  map::Map venue = *map_;
  venue.rooms = {"west", "east"};
  const int room_of_keyframe[] = {0, 1, 0, 1};  // GraffitiKeyframes(): centre, right, left, low
  for (std::size_t k = 0; k < venue.keyframes.size(); ++k) venue.keyframes[k].room = room_of_keyframe[k];
  Tracker tracker(venue);
  const FrameResult right = tracker.Track(world_->Render(LookAt({0.27, 0.02, -0.85}, {0.05, 0, 0})), 0.0);
  ASSERT_NE(right.status, TrackStatus::kLost) << right.reason;
  EXPECT_EQ(right.room, "east");
  const FrameResult left = tracker.Track(world_->Render(LookAt({-0.27, 0.08, -0.85}, {-0.05, 0, 0})), 1.0);
  ASSERT_NE(left.status, TrackStatus::kLost) << left.reason;
  EXPECT_EQ(left.room, "west");
  const FrameResult lost = tracker.Track(cv::Mat(world_->Render(PathPose(0)).size(), CV_8UC3, cv::Scalar::all(0)), 2.0);
  EXPECT_EQ(lost.status, TrackStatus::kLost);
  EXPECT_EQ(lost.room, "");
  Tracker plain(*map_);
  EXPECT_EQ(plain.Track(world_->Render(PathPose(0)), 0.0).room, "") << "a map without rooms";
}

// Fresh features: a tracked frame far from the last one in time (by default over 0.25 s: photos,
// a sub-sampled clip) is posed again from its own SIFT matched against the whole map, and that
// pose (close to the truth) is kept; frames at a video's rate are left to the flow, as with
// fresh_features_after_s = -1 (never), unless it is 0 (every tracked frame).
TEST_F(PlanarTrackerTest, FreshFeaturesPoseTrackedFramesFarApartFromGlobalMatches) {
  struct Run {
    const char* what;
    double after_s;       // fresh_features_after_s
    double frame_gap_s;   // between the frames' timestamps
    bool fresh_expected;  // on the tracked frames
  };
  const double kDefault = TrackingOptions{}.fresh_features_after_s;
  for (const Run run : {Run{"photos 1 s apart, the default", kDefault, 1.0, true},
                        Run{"video at 10 fps, the default", kDefault, 0.1, false},
                        Run{"video at 10 fps, every frame", 0.0, 0.1, true},
                        Run{"photos 1 s apart, never", -1.0, 1.0, false}}) {
    SCOPED_TRACE(run.what);
    TrackerOptions options;
    options.tracking.fresh_features_after_s = run.after_s;
    Tracker tracker(*map_, options);
    int tracked = 0, fresh = 0;
    for (int i = 0; i < 10; ++i) {
      const calib::Pose truth = PathPose(3 * i);  // frames 12 mm apart
      const FrameResult r = tracker.Track(world_->Render(truth), i * run.frame_gap_s);
      ASSERT_NE(r.status, TrackStatus::kLost) << "frame " << i << ": " << r.reason;
      ExpectNear(r, truth, 0.003, 0.2);
      if (r.status != TrackStatus::kTracking) continue;
      ++tracked;
      if (r.fresh_inliers > 0) {
        ++fresh;
        EXPECT_EQ(r.inliers, r.fresh_inliers);
        EXPECT_GT(r.matches, 0) << "frame " << i;
      }
    }
    ASSERT_GE(tracked, 8);
    if (run.fresh_expected) {
      EXPECT_GE(fresh, tracked - 1);
    } else {
      EXPECT_EQ(fresh, 0);
    }
  }
}

// A relocalization without a prior pose extracts COLMAP's weaker keypoints (contrast 0.02);
// flow would carry their localization error along, so the next frame starts from guided
// matching around the relocalised pose. With relocalization at guided matching's threshold its
// inliers are followed by flow.
TEST_F(PlanarTrackerTest, FlowFollowsARelocalizationOnlyOnKeypointsAsStrongAsGuidedMatchings) {
  for (const double contrast : {0.02, 0.04}) {
    TrackerOptions options;
    options.relocalization.features.contrast_threshold = contrast;
    Tracker tracker(*map_, options);
    const FrameResult first = tracker.Track(world_->Render(PathPose(0)), 0.0);
    ASSERT_EQ(first.status, TrackStatus::kRelocalized) << first.reason;
    const FrameResult next = tracker.Track(world_->Render(PathPose(1)), 1 / 30.0);
    ASSERT_EQ(next.status, TrackStatus::kTracking) << next.reason;
    ExpectNear(next, PathPose(1), 0.003, 0.2);
    if (contrast < options.tracking.guided_contrast_threshold) {
      EXPECT_EQ(next.flow_tracks, 0) << "contrast " << contrast;
      EXPECT_GE(next.guided_matches, options.tracking.min_inliers) << "contrast " << contrast;
    } else {
      EXPECT_GT(next.flow_tracks, options.tracking.min_inliers) << "contrast " << contrast;
    }
    // Tracked frames are followed by flow either way: no further SIFT.
    for (int i = 2; i < 6; ++i) {
      const FrameResult r = tracker.Track(world_->Render(PathPose(i)), i / 30.0);
      ASSERT_EQ(r.status, TrackStatus::kTracking) << r.reason;
      EXPECT_GT(r.flow_tracks, options.tracking.min_inliers) << "contrast " << contrast << ", frame " << i;
      EXPECT_EQ(r.keypoints, 0) << "contrast " << contrast << ", frame " << i;
    }
  }
}

// WarmUp runs each step on a blank frame and must leave nothing behind: the same poses, bit for
// bit, as a tracker that did not warm up, from the first frame (a relocalization) on.
TEST_F(PlanarTrackerTest, WarmUpChangesNoResult) {
  Tracker cold(*map_);
  Tracker warm(*map_);
  warm.WarmUp();
  for (int i = 0; i < 5; ++i) {
    const cv::Mat frame = world_->Render(PathPose(i));
    const FrameResult a = cold.Track(frame, i / 30.0);
    const FrameResult b = warm.Track(frame, i / 30.0);
    ASSERT_NE(a.status, TrackStatus::kLost) << "frame " << i << ": " << a.reason;
    EXPECT_EQ(a.status, b.status) << "frame " << i;
    EXPECT_EQ(a.inliers, b.inliers) << "frame " << i;
    EXPECT_EQ(a.pose.q_cw.coeffs(), b.pose.q_cw.coeffs()) << "frame " << i;
    EXPECT_EQ(a.pose.t_cw, b.pose.t_cw) << "frame " << i;
  }
}

// Replenishment with guided matching's SIFT extracted ahead on a worker
// thread and used `prefetch_lag_frames` later, its keypoints followed by LK into that frame.
// Used exactly on schedule (the frame count decides, not the worker's timing: two runs give the
// same poses bit for bit), and as exact as tracking without it.
TEST_F(PlanarTrackerTest, FeaturesExtractedAheadAreUsedOnScheduleAndKeepThePoseExact) {
  TrackerOptions options;
  options.tracking.prefetch_below = 100000;  // every tracked frame without one pending starts one
  options.tracking.prefetch_lag_frames = 3;
  options.tracking.replenish_below = 0;      // no guided matching in the frame itself
  auto run = [&] {
    Tracker tracker(*map_, options);
    std::vector<FrameResult> results;
    for (int i = 0; i < 30; ++i) results.push_back(tracker.Track(world_->Render(PathPose(i)), i / 30.0));
    return results;
  };
  const std::vector<FrameResult> first = run(), second = run();
  for (int i = 0; i < 30; ++i) {
    const FrameResult& r = first[i];
    ASSERT_NE(r.status, TrackStatus::kLost) << "frame " << i << ": " << r.reason;
    ExpectNear(r, PathPose(i), 0.003, 0.2);
    // Frame 0 is relocalised; frame 1, the first tracked, starts an extraction that frame 4 uses
    // and frame 4 starts the next one.
    const bool due = i >= 4 && (i - 1) % 3 == 0;
    if (due) {
      EXPECT_GT(r.prefetched_matches, 20) << "frame " << i;
      EXPECT_GT(r.keypoints, 0) << "frame " << i;
      EXPECT_GT(r.times.extract_ms, 0) << "frame " << i << ": the worker's CPU belongs to the frame that uses it";
      EXPECT_GE(r.times.cpu_ms, r.times.extract_ms) << "frame " << i;
    } else {
      EXPECT_EQ(r.prefetched_matches, 0) << "frame " << i;
    }
    EXPECT_EQ(r.pose.t_cw, second[i].pose.t_cw) << "frame " << i;
    EXPECT_EQ(r.pose.q_cw.coeffs(), second[i].pose.q_cw.coeffs()) << "frame " << i;
  }
}

// A live source (TrackingOptions::background): the first frame's relocalization runs on the
// worker while frames keep coming (a camera held still), and the first frame that finds it done
// follows its inliers into itself; then guided matching's SIFT is only ever extracted ahead, and
// frames use it when it is done, without waiting. Frames come at 30 fps, as from a camera.
TEST_F(PlanarTrackerTest, InTheBackgroundNoFrameWaitsForSiftOrRelocalization) {
  TrackerOptions options;
  options.tracking.background = true;
  options.tracking.prefetch_below = 100000;  // every tracked frame without one pending starts one
  Tracker tracker(*map_, options);
  // 30 fps, slower by as much as a sanitizer slows the worker: what is checked is the order of
  // the frames and the worker's results, which a 5x slower worker at full rate would not reach.
  const auto frame_interval = std::chrono::microseconds(static_cast<long>(33333 * arview::testing::kSanitizerSlowdown));
  auto at_camera_rate = [next = std::chrono::steady_clock::now(), frame_interval]() mutable {
    next += frame_interval;
    std::this_thread::sleep_until(next);
  };
  const cv::Mat still = world_->Render(PathPose(0));
  FrameResult first = tracker.Track(still, 0);
  EXPECT_EQ(first.status, TrackStatus::kLost);
  EXPECT_TRUE(first.awaiting_relocalization) << first.reason;
  EXPECT_EQ(first.keypoints, 0) << "the first frame extracted SIFT itself";
  int waited = 0;
  FrameResult r = first;
  while (r.status == TrackStatus::kLost && waited < 300) {  // 10 s at 30 fps
    at_camera_rate();
    ++waited;
    r = tracker.Track(still, waited / 30.0);
  }
  ASSERT_EQ(r.status, TrackStatus::kRelocalized) << "after " << waited << " frames: " << r.reason;
  EXPECT_GE(r.relocalized_frames_ago, 1);
  EXPECT_GT(r.flow_tracks, 30) << "the relocalization's inliers followed into the frame that used it";
  ExpectNear(r, PathPose(0), 0.003, 0.2);

  // 45 frames along the arc and back, on until two frames have used features extracted ahead
  // (10 s at most): a loaded machine gives the worker, at a lower priority, its turn late.
  int frames_using_features_extracted_ahead = 0;
  for (int i = 1; i <= 300 && (i <= 45 || frames_using_features_extracted_ahead < 2); ++i) {
    at_camera_rate();
    const int along = 45 - std::abs(45 - i % 90);  // 0 .. 45 .. 0
    r = tracker.Track(world_->Render(PathPose(along)), (waited + i) / 30.0);
    ASSERT_EQ(r.status, TrackStatus::kTracking) << "frame " << i << ": " << r.reason;
    ExpectNear(r, PathPose(along), 0.003, 0.2);
    // Guided matches come only from features extracted ahead; the wide search (SIFT in line) never runs.
    EXPECT_EQ(r.guided_matches, r.prefetched_matches) << "frame " << i;
    EXPECT_EQ(r.wide_matches, 0) << "frame " << i;
    if (r.prefetched_matches > 0) ++frames_using_features_extracted_ahead;
  }
  EXPECT_GE(frames_using_features_extracted_ahead, 2);
}

// Frames of a scene the map does not hold, in the background: each is lost at once while the
// worker tries; the tracker is destroyed with a relocalization running. Two seconds of frames
// at 30 fps, slower by as much as a sanitizer slows the worker's relocalization (as above).
TEST_F(PlanarTrackerTest, InTheBackgroundAnUnknownSceneIsLostWithoutWaiting) {
  TrackerOptions options;
  options.tracking.background = true;
  options.tracking.prefetch_below = 200;
  auto tracker = std::make_unique<Tracker>(*map_, options);
  cv::Mat noise(map_->camera.Size(), CV_8U);
  cv::randu(noise, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(5, 5), 1.5);
  const int frames = 60;
  const auto frame_interval = std::chrono::microseconds(static_cast<long>(33333 * arview::testing::kSanitizerSlowdown));
  bool a_relocalization_failed = false;
  for (int i = 0; i < frames; ++i) {
    std::this_thread::sleep_for(frame_interval);
    const FrameResult r = tracker->Track(noise, i / 30.0);
    ASSERT_EQ(r.status, TrackStatus::kLost) << "frame " << i;
    EXPECT_EQ(r.keypoints > 0, r.relocalization_failure != PoseFailure::kNone) << "frame " << i << ": " << r.reason;
    if (r.relocalization_failure != PoseFailure::kNone) a_relocalization_failed = true;
  }
  EXPECT_TRUE(a_relocalization_failed) << "no relocalization finished in " << frames << " frames";
  tracker->Track(noise, frames / 30.0);  // starts another
  tracker.reset();
}

// A whip-pan: the camera pans slowly, then turns 8 degrees a frame for three frames, each smeared
// over 6 degrees (~55 px) by the exposure, then pans slowly again. Flow and SIFT find too little
// in the smeared frames (without image alignment they are lost); image alignment keeps their
// rotation within about a degree, and features take over again afterwards.
TEST_F(PlanarTrackerTest, WhipPanFramesTakeTheirRotationFromImageAlignment) {
  const Eigen::Vector3d centre(0.02, 0.01, -0.85);
  auto turned = [&](double yaw_deg) {
    const calib::Pose straight = LookAt(centre, {0.02, 0.01, 0});
    calib::Pose pose = straight;
    pose.q_cw = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()) * straight.q_cw;
    pose.t_cw = -(pose.q_cw * centre);
    return pose;
  };
  auto smeared = [&](double yaw_a, double yaw_b) {
    cv::Mat sum = cv::Mat::zeros(map_->camera.Size(), CV_32F);
    const int samples = 24;
    for (int s = 0; s < samples; ++s) {
      cv::Mat render;
      world_->Render(turned(yaw_a + (s + 0.5) / samples * (yaw_b - yaw_a))).convertTo(render, CV_32F);
      sum += render;
    }
    cv::Mat out;
    sum.convertTo(out, CV_8U, 1.0 / samples);
    return out;
  };
  // Yaw per frame: slow from -12 to -9 degrees, then three fast frames, then slow from +15.
  std::vector<double> yaws;
  for (int i = 0; i < 10; ++i) yaws.push_back(-12 + 0.3 * i);
  for (int i = 1; i <= 3; ++i) yaws.push_back(-9.3 + 8 * i);
  for (int i = 1; i <= 6; ++i) yaws.push_back(14.7 + 0.3 * i);
  auto run = [&](double align_max_seconds) {
    TrackerOptions options;
    options.tracking.align_max_seconds = align_max_seconds;
    Tracker tracker(*map_, options);
    std::vector<FrameResult> results;
    for (size_t i = 0; i < yaws.size(); ++i) {
      const bool fast = i >= 10 && i < 13;
      const cv::Mat frame = fast ? smeared(yaws[i] - 3, yaws[i] + 3) : world_->Render(turned(yaws[i]));
      results.push_back(tracker.Track(frame, i / 30.0));
    }
    return results;
  };
  const std::vector<FrameResult> without = run(0);
  for (int i = 10; i < 13; ++i)
    EXPECT_EQ(without[i].status, TrackStatus::kLost) << "frame " << i << ": the test needs frames features cannot pose";
  const std::vector<FrameResult> with = run(0.5);
  for (size_t i = 0; i < yaws.size(); ++i) {
    const FrameResult& r = with[i];
    ASSERT_NE(r.status, TrackStatus::kLost) << "frame " << i << ": " << r.reason;
    SCOPED_TRACE("frame " + std::to_string(i));
    const bool fast = i >= 10 && i < 13;
    if (fast) {
      EXPECT_EQ(r.status, TrackStatus::kTracking) << "frame " << i;
      EXPECT_GT(r.align_zncc, 0.85) << "frame " << i;
      EXPECT_EQ(r.inliers, 0) << "frame " << i;
      ExpectNear(r, turned(yaws[i]), 0.01, 1.5);  // 0.5 degrees a frame, chained (1.1 at the third)
    } else {
      EXPECT_EQ(r.align_zncc, 0) << "frame " << i;
      ExpectNear(r, turned(yaws[i]), 0.003, 0.2);
    }
  }
}

TEST_F(PlanarTrackerTest, FrameOfAnotherSceneIsLostNotAPose) {
  Tracker tracker(*map_);
  for (const char* name : {"left01.jpg", "box_in_scene.png", "fruits.jpg"}) {
    cv::Mat other = cv::imread(std::string(kOpenCvData) + name);
    ASSERT_FALSE(other.empty()) << name;
    cv::resize(other, other, map_->camera.Size());
    const FrameResult r = tracker.Track(other, 0.0);
    EXPECT_EQ(r.status, TrackStatus::kLost) << name << ": " << r.inliers << " inliers";
    EXPECT_FALSE(r.reason.empty());
  }
}

TEST_F(PlanarTrackerTest, BlackAndTinyFramesAreLost) {
  Tracker tracker(*map_);
  const FrameResult black = tracker.Track(cv::Mat::zeros(map_->camera.Size(), CV_8UC3), 0.0);
  EXPECT_EQ(black.status, TrackStatus::kLost);
  EXPECT_NE(black.reason.find("relocalization failed"), std::string::npos) << black.reason;
  const FrameResult tiny = tracker.Track(cv::Mat::zeros(4, 4, CV_8U), 0.1);
  EXPECT_EQ(tiny.status, TrackStatus::kLost);
  EXPECT_NE(tiny.reason.find("4x4"), std::string::npos) << tiny.reason;
  EXPECT_EQ(tracker.Track(cv::Mat(), 0.2).status, TrackStatus::kLost);
  // Lost frames drop the prior: a good frame afterwards is a relocalization.
  const FrameResult good = tracker.Track(world_->Render(PathPose(0)), 0.3);
  EXPECT_EQ(good.status, TrackStatus::kRelocalized) << good.reason;
}

TEST_F(PlanarTrackerTest, MapWithTooFewPointsIsAClearErrorAtLoad) {
  map::Map small = *map_;
  small.points.resize(10);
  small.keyframes.clear();
  small.descriptors = small.descriptors.rowRange(0, 10).clone();
  small.descriptor_point.resize(10);
  try {
    Tracker tracker(small);
    FAIL() << "a 10-point map was accepted";
  } catch (const TrackerError& e) {
    EXPECT_NE(std::string(e.what()).find("map has 10 points"), std::string::npos) << e.what();
  }
}

TEST_F(PlanarTrackerTest, InconsistentMapIsRefusedWithTheReason) {
  map::Map broken = *map_;
  broken.descriptor_point.pop_back();
  try {
    Tracker tracker(broken);
    FAIL() << "an inconsistent map was accepted";
  } catch (const TrackerError& e) {
    EXPECT_NE(std::string(e.what()).find("descriptor"), std::string::npos) << e.what();
  }
  CheckTrackable(*map_, 30);
}

TEST(ConstantVelocity, PredictionRepeatsTheLastMotion) {
  const calib::Pose a = LookAt({0, 0, -1}, {0, 0, 0});
  const calib::Pose b = LookAt({0.1, 0, -1}, {0.05, 0, 0});
  const calib::Pose c = PredictConstantVelocity(b, RelativeMotion(a, b));
  EXPECT_NEAR((c.Center() - Eigen::Vector3d(0.2, 0, -1)).norm(), 0, 0.02);
  const calib::Pose same = PredictConstantVelocity(b, RelativeMotion(b, b));
  EXPECT_LT((same.t_cw - b.t_cw).norm(), 1e-12);
}

TEST(CentreFitter, ExtrapolatesTheLineAndDampsOneNoisyCentre) {
  CentreFitter fitter(16, 1.0);
  EXPECT_TRUE(fitter.empty());
  const Eigen::Vector3d start(1, 2, 3), velocity(0.3, 0, -0.1);
  fitter.Add(0.0, start);
  EXPECT_TRUE(fitter.At(0.5).isApprox(start));  // one centre: no velocity
  for (int i = 1; i < 15; ++i) fitter.Add(i / 30.0, start + velocity * (i / 30.0));
  EXPECT_NEAR((fitter.At(0.8) - (start + velocity * 0.8)).norm(), 0.0, 1e-9);
  // A 16th centre 3 cm off: the line through it moves by under a quarter of that there.
  const double t = 15 / 30.0;
  fitter.Add(t, start + velocity * t + Eigen::Vector3d(0.03, 0, 0));
  EXPECT_LT((fitter.At(t) - (start + velocity * t)).norm(), 0.0075);
  // Centres older than the span, or beyond the count, are forgotten.
  fitter.Add(3.0, Eigen::Vector3d::Zero());
  EXPECT_TRUE(fitter.At(4.0).isApprox(Eigen::Vector3d::Zero()));
  fitter.Clear();
  EXPECT_TRUE(fitter.empty());
}

TEST(SpreadTracks, KeepsAtMostTheCountSpreadOverTheImage) {
  Track2D3D tracks;
  // 100 tracks crowded in the top-left cell, 10 spread along the bottom row.
  for (int i = 0; i < 100; ++i) {
    tracks.pixels.emplace_back(1.0f + i * 0.1f, 2.0f);
    tracks.points.push_back(i);
  }
  for (int i = 0; i < 10; ++i) {
    tracks.pixels.emplace_back(50.0f + 60.0f * i, 470.0f);
    tracks.points.push_back(1000 + i);
  }
  const Track2D3D spread = SpreadTracks(tracks, 20, 40, {640, 480});
  ASSERT_EQ(spread.pixels.size(), 20u);
  int bottom = 0;
  for (std::uint32_t p : spread.points) bottom += p >= 1000;
  EXPECT_EQ(bottom, 10) << "every sparse cell must keep its track before crowded cells get more";
  EXPECT_EQ(SpreadTracks(tracks, 500, 40, {640, 480}).pixels.size(), 110u);
}

TEST(ColmapDescriptors, RootL1TimesFiveHundredTwelveClamped) {
  cv::Mat sift = cv::Mat::zeros(2, 128, CV_32F);
  sift.at<float>(0, 0) = 3;
  sift.at<float>(0, 1) = 1;  // L1 = 4: sqrt(0.75)*512 = 443.4 → 255, sqrt(0.25)*512 = 256 → 255
  for (int c = 0; c < 128; ++c) sift.at<float>(1, c) = 2;  // sqrt(1/128)*512 = 45.25 → 45
  const cv::Mat out = ToColmapDescriptors(sift);
  ASSERT_EQ(out.type(), CV_8U);
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 255);
  EXPECT_EQ(out.at<std::uint8_t>(0, 1), 255);
  EXPECT_EQ(out.at<std::uint8_t>(0, 2), 0);
  EXPECT_EQ(out.at<std::uint8_t>(1, 77), 45);
  EXPECT_EQ(ToColmapDescriptors(cv::Mat()).rows, 0);
}

TEST(SiftExtractor, TinyAndEmptyImagesGiveNoFeatures) {
  const SiftExtractor sift;
  EXPECT_TRUE(sift.Extract(cv::Mat()).keypoints.empty());
  EXPECT_TRUE(sift.Extract(cv::Mat::zeros(8, 8, CV_8U)).keypoints.empty());
  EXPECT_EQ(sift.Extract(cv::Mat::zeros(8, 8, CV_8U)).descriptors.cols, 128);
}

TEST(OneEuroFilter, SmoothsJitterAtRestAndFollowsMotion) {
  OneEuroFilter filter({1.0, 0.5, 1.0});
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0, 0.002);
  double raw_var = 0, filtered_var = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d x(noise(rng), noise(rng), noise(rng));
    const Eigen::Vector3d y = filter.Filter(x, i / 30.0);
    if (i > 30) {
      raw_var += x.squaredNorm();
      filtered_var += y.squaredNorm();
    }
  }
  EXPECT_LT(filtered_var, 0.25 * raw_var);
  // A step: the filter converges to the new position.
  Eigen::Vector3d y;
  for (int i = 300; i < 400; ++i) y = filter.Filter(Eigen::Vector3d(1, 0, 0), i / 30.0);
  EXPECT_NEAR(y.x(), 1.0, 1e-3);
  // Time going backwards restarts at the input.
  EXPECT_EQ(filter.Filter(Eigen::Vector3d(5, 5, 5), 0.0), Eigen::Vector3d(5, 5, 5));
}

}  // namespace
}  // namespace arview::tracker
