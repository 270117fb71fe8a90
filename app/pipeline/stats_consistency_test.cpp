// One median definition: the same numbers give the same median whether they go through
// stats.json (the pipeline's stage timings and gaze errors) or `arview eval` (trajectory errors).
// Before base/stats.h, stats.json quoted the lower middle sample and eval the mean of the two
// middle ones, so an even count gave two different "medians".

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/pipeline/pipeline_report.h"
#include "app/pipeline/stage_stats.h"
#include "recordings/accuracy.h"

namespace arview::app {
namespace {

// An even count, so that the median definitions in use before differed: 0.25 + 0.5 over 2.
const std::vector<double> kNumbers{0.75, 0.1, 0.5, 2.0, 0.25, 0.05};
constexpr double kMedian = 0.375;

double StatsJsonStageMedian() {
  StageStats stats;
  for (double v : kNumbers) stats.Record("track", v);
  PipelineReport report;
  report.stages = stats.Summaries();
  for (double v : kNumbers) report.gaze_error_deg.Add(v);
  const nlohmann::json j = nlohmann::json::parse(PipelineSummaryJson(report, "test").dump());
  EXPECT_DOUBLE_EQ(j["gaze"]["median_error_deg"].get<double>(), j["stages"]["track"]["median_ms"].get<double>());
  return j["stages"]["track"]["median_ms"].get<double>();
}

double EvalMedian() {
  // Ground truth at the origin; each estimate off by one of the numbers along x.
  recordings::Trajectory groundtruth, estimate;
  for (size_t i = 0; i < kNumbers.size(); ++i) {
    const double t = static_cast<double>(i);
    groundtruth.push_back({t, calib::Pose{}});
    estimate.push_back({t, calib::Pose::FromCameraToWorld(Eigen::Quaterniond::Identity(), {kNumbers[i], 0, 0})});
  }
  recordings::AccuracyOptions options;
  options.align = recordings::AlignMode::kNone;
  const recordings::AccuracyReport report = recordings::EvaluateTrajectory(estimate, groundtruth, options);
  const nlohmann::json j = nlohmann::json::parse(recordings::ReportToJson(report));
  EXPECT_DOUBLE_EQ(j["ate"]["median"].get<double>(), report.ate.median);
  return report.ate.median;
}

TEST(OneMedian, StatsJsonAndEvalGiveTheSameMedianOfTheSameNumbers) {
  const double from_stats = StatsJsonStageMedian();
  const double from_eval = EvalMedian();
  EXPECT_DOUBLE_EQ(from_stats, kMedian);
  EXPECT_DOUBLE_EQ(from_eval, kMedian);
  EXPECT_DOUBLE_EQ(from_stats, from_eval);
}

// A character with eyes (anim/gaze.h): each frame's record says whether they were on the viewer
// and which blinks began, the summary and the report count them; without eyes, nothing.
TEST(StatsConsistency, EyesOnTheViewerAndBlinksAreRecordedPerFrameAndCounted) {
  PipelineReport report;
  FrameLog plain;
  EXPECT_FALSE(FrameLogJson(plain).contains("eyes_on_viewer"));
  CountEyes(plain, report);
  EXPECT_FALSE(PipelineSummaryJson(report, "test").contains("eyes"));
  EXPECT_EQ(PipelineReportText(report).find("eyes:"), std::string::npos);
  for (int i = 0; i < 4; ++i) {
    FrameLog f;
    f.eyes.active = true;
    f.eyes.eyes_on_viewer = i != 2;
    f.eyes.blinking = i == 1;
    f.eyes.blinks_begun = i == 1 ? 1 : 0;
    const nlohmann::ordered_json j = FrameLogJson(f);
    EXPECT_EQ(j.at("eyes_on_viewer").get<bool>(), i != 2);
    EXPECT_EQ(j.at("blinking").get<bool>(), i == 1);
    EXPECT_EQ(j.contains("blinks_begun"), i == 1);
    CountEyes(f, report);
  }
  const nlohmann::ordered_json summary = PipelineSummaryJson(report, "test");
  EXPECT_EQ(summary.at("eyes").at("frames").get<int>(), 4);
  EXPECT_EQ(summary.at("eyes").at("on_viewer_frames").get<int>(), 3);
  EXPECT_DOUBLE_EQ(summary.at("eyes").at("on_viewer_share").get<double>(), 0.75);
  EXPECT_EQ(summary.at("eyes").at("blinks").get<int>(), 1);
  EXPECT_NE(PipelineReportText(report).find("eyes: on the viewer in 3 of 4 frames (75%), 1 blinks"), std::string::npos);
}

}  // namespace
}  // namespace arview::app

namespace arview::app {
namespace {

// A venue's map: each localized frame's record names the room the tracker put it in; a frame
// of a map without rooms has no "room".
TEST(StatsConsistency, TheRoomOfAVenuesFrameIsRecorded) {
  FrameLog plain;
  plain.track.status = tracker::TrackStatus::kTracking;
  EXPECT_FALSE(FrameLogJson(plain).contains("room"));
  FrameLog in_venue = plain;
  in_venue.track.room = "east";
  EXPECT_EQ(FrameLogJson(in_venue).at("room"), "east");
}

// A character with a face speech drives (anim/face.h): each frame's record has the mouth's
// opening, the strongest viseme while it talks, and the line being said; without a face, none.
TEST(StatsConsistency, TheMouthTheVisemeAndTheLineAreRecordedPerFrame) {
  FrameLog plain;
  const nlohmann::ordered_json none = FrameLogJson(plain);
  EXPECT_FALSE(none.contains("mouth_open"));
  EXPECT_FALSE(none.contains("viseme"));
  EXPECT_FALSE(none.contains("saying"));
  FrameLog silent;
  silent.face.active = true;
  const nlohmann::ordered_json s = FrameLogJson(silent);
  EXPECT_EQ(s.at("mouth_open").get<double>(), 0.0);
  EXPECT_FALSE(s.contains("viseme"));
  EXPECT_FALSE(s.contains("saying"));
  FrameLog talking;
  talking.face.active = true;
  talking.face.talking = 1;
  talking.face.jaw_open = 0.5f;
  talking.face.viseme = 10;  // aa
  const std::string line = "Hello there!";
  talking.saying = line;
  const nlohmann::ordered_json t = FrameLogJson(talking);
  EXPECT_DOUBLE_EQ(t.at("mouth_open").get<double>(), 0.5);
  EXPECT_EQ(t.at("viseme").get<std::string>(), "aa");
  EXPECT_EQ(t.at("saying").get<std::string>(), line);
}

}  // namespace
}  // namespace arview::app
