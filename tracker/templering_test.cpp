// The tracker on real photographs against a real COLMAP map: templeRing (Middlebury), a map
// from the 24 even frames, the 23 odd frames localised and judged against the ground truth
// with the alignment fitted on the map's keyframes (never on the judged frames). The map is
// built once for every test process of the user (mapping/test_temple_map.h), with 2048
// features per image to keep COLMAP's exhaustive matching short (a partial arc of the ring
// splits into several small models, so the whole ring is mapped).

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "mapping/colmap_pipeline.h"
#include "mapping/test_temple_map.h"
#include "recordings/accuracy.h"
#include "recordings/importers.h"
#include "recordings/recording.h"
#include "tests/support/test_data.h"
#include "tracker/tracker.h"

namespace arview::tracker {
namespace {

namespace fs = std::filesystem;

bool ColmapOnPath() { return std::system("colmap -h > /dev/null 2>&1") == 0; }

class TempleRingTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path source = arview::testing::SharedData("templeRing");
    if (!fs::exists(source) || !ColmapOnPath()) return;
    recording_ = std::make_unique<recordings::Recording>();
    mapping::MapBuildOptions options;
    options.frames_spec = "0-46:2";
    options.matcher = mapping::MatcherKind::kExhaustive;
    options.max_num_features = 2048;
    map_ = std::make_unique<map::Map>(
        arview::testing::BuildSharedTempleMap(source, recording_.get(), "tracker_map", options).map);
  }
  static void TearDownTestSuite() {
    map_.reset();
    recording_.reset();
  }
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(arview::testing::SharedData("templeRing"), "../shared/data");
    if (!ColmapOnPath()) GTEST_SKIP() << "needs COLMAP on PATH (Debian package colmap)";
    ASSERT_TRUE(map_) << "the templeRing map was not built";
  }

  static recordings::Trajectory Keyframes() {
    recordings::Trajectory t;
    for (const auto& k : map_->keyframes) t.push_back({k.timestamp, k.pose});
    return t;
  }

  static std::unique_ptr<recordings::Recording> recording_;
  static std::unique_ptr<map::Map> map_;
};
std::unique_ptr<recordings::Recording> TempleRingTest::recording_;
std::unique_ptr<map::Map> TempleRingTest::map_;

TEST_F(TempleRingTest, LocalizesEveryOddFrameToAboutAMillimetre) {
  ASSERT_EQ(map_->keyframes.size(), 24u);
  Tracker tracker(*map_);
  recordings::Trajectory estimate;
  for (int i = 1; i <= 45; i += 2) {
    tracker.Reset();  // frames are 15° apart: each one is a relocalization
    const FrameResult r = tracker.Track(recording_->ReadImage(i), recording_->frames[i].timestamp);
    ASSERT_EQ(r.status, TrackStatus::kRelocalized) << "frame " << i << ": " << r.reason;
    EXPECT_LT(r.rms_px, 1.0) << "frame " << i;
    EXPECT_GE(r.inliers, 50) << "frame " << i;
    estimate.push_back({recording_->frames[i].timestamp, r.pose});
  }
  const recordings::Trajectory keyframes = Keyframes();
  recordings::AccuracyOptions options;
  options.align = recordings::AlignMode::kSim3;
  options.align_with = &keyframes;
  const auto report = recordings::EvaluateTrajectory(estimate, *recording_->groundtruth, options);
  EXPECT_EQ(report.associated, 23);
  std::printf("templeRing odd frames: median centre error %.3f mm, max %.3f mm\n", 1e3 * report.ate.median,
              1e3 * report.ate.max);
  EXPECT_LT(report.ate.median, 0.0015) << "median centre error " << report.ate.median << " m";
  EXPECT_LT(report.ate.max, 0.005) << "max centre error " << report.ate.max << " m";
}

TEST_F(TempleRingTest, AnotherSceneBlackAndTinyFramesAreLost) {
  Tracker tracker(*map_);
  const std::string data = "/usr/share/doc/opencv-doc/examples/data/";
  for (const char* name : {"left01.jpg", "building.jpg", "baboon.jpg"}) {
    cv::Mat other = cv::imread(data + name);
    if (other.empty()) continue;
    cv::resize(other, other, map_->camera.Size());
    const FrameResult r = tracker.Track(other, 0.0);
    EXPECT_EQ(r.status, TrackStatus::kLost) << name << ": " << r.inliers << " inliers, rms " << r.rms_px;
  }
  EXPECT_EQ(tracker.Track(cv::Mat::zeros(map_->camera.Size(), CV_8UC3), 1.0).status, TrackStatus::kLost);
  const FrameResult tiny = tracker.Track(cv::Mat::zeros(3, 2, CV_8UC3), 2.0);
  EXPECT_EQ(tiny.status, TrackStatus::kLost);
  EXPECT_FALSE(tiny.reason.empty());
}

TEST_F(TempleRingTest, JumpInTheSequenceIsRelocalized) {
  Tracker tracker(*map_);
  // Frames 1 then 25: half way round the temple, far beyond what the motion prior can follow.
  ASSERT_EQ(tracker.Track(recording_->ReadImage(1), 1.0).status, TrackStatus::kRelocalized);
  const FrameResult r = tracker.Track(recording_->ReadImage(25), 2.0);
  EXPECT_EQ(r.status, TrackStatus::kRelocalized) << r.reason;
  EXPECT_FALSE(r.reason.empty()) << "the failed tracking attempt should be explained";
}

}  // namespace
}  // namespace arview::tracker
