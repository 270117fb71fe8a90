#include "tracker/loss_diagnosis.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <memory>

#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"
#include "tracker/test_scene.h"
#include "tracker/working_resolution.h"

namespace arview::tracker {
namespace {

using testing::LookAt;
using testing::PlanarWorld;
using testing::TestCamera;

const std::string kOpenCvData = "/usr/share/doc/opencv-doc/examples/data/";

// Each kind of lost frame made from a view the map covers (or from another scene), tracked, and
// its cause recognised from its numbers. The map: the graffiti plane of tracker_test.cpp; the
// reference: its keyframes' renderings, as a session reads a map's keyframe images.
class LossDiagnosisTest : public ::testing::Test {
 protected:
  void SetUp() override {
    plane_ = testing::SharedGraffitiPlane();
    ARVIEW_REQUIRE_DATA_PATH(testing::kGraffitiTexture, "Debian package opencv-doc");
    ASSERT_TRUE(plane_);
    std::vector<cv::Mat> images;
    for (const calib::Pose& pose : testing::GraffitiKeyframes()) images.push_back(plane_->world.Render(pose));
    reference_ = ReferenceFromImages(images);
  }

  // A view between the keyframes: the map covers it.
  static calib::Pose MappedView() { return LookAt({0.08, 0.04, -0.8}, {0.02, 0.01, 0}); }
  cv::Mat RenderMappedView() const { return plane_->world.Render(MappedView()); }
  const map::Map& map() const { return plane_->map; }

  // `frame` tracked on a fresh tracker: it must be lost; then its diagnosis, the frames coming
  // from `frame_camera`.
  LossDiagnosis TrackLostAndDiagnose(const cv::Mat& frame, const calib::Camera& frame_camera) const {
    Tracker tracker(map());
    const FrameResult r = tracker.Track(frame, 0.0);
    EXPECT_EQ(r.status, TrackStatus::kLost) << r.inliers << " inliers";
    return LossDiagnoser(map().camera, frame_camera, reference_).Diagnose(frame, r);
  }

  const testing::GraffitiPlane* plane_ = nullptr;
  AppearanceReference reference_;
};

TEST_F(LossDiagnosisTest, TheMappedViewItselfIsFound) {
  // What the other tests degrade localizes as it is: the degradation, not the view, loses them.
  Tracker tracker(map());
  EXPECT_NE(tracker.Track(RenderMappedView(), 0.0).status, TrackStatus::kLost);
  EXPECT_EQ(reference_.images, 4);
  EXPECT_GT(reference_.brightness, 60);
  EXPECT_LT(reference_.blur, 0.4);
}

TEST_F(LossDiagnosisTest, ABrightSharpViewOfAnotherSceneIsOutsideTheMap) {
  for (const char* name : {"box_in_scene.png", "fruits.jpg"}) {
    cv::Mat other = cv::imread(kOpenCvData + name);
    ASSERT_FALSE(other.empty()) << name;
    cv::resize(other, other, map().camera.Size());
    const LossDiagnosis d = TrackLostAndDiagnose(other, map().camera);
    EXPECT_EQ(d.cause, LossCause::kOutsideMap) << name << ": " << d.detail;
    EXPECT_NE(d.detail.find(" matches of "), std::string::npos) << d.detail;
  }
}

TEST_F(LossDiagnosisTest, TheMappedViewInDimLightIsTooDark) {
  cv::Mat dim;
  RenderMappedView().convertTo(dim, -1, 0.04);  // a twenty-fifth of the light
  const LossDiagnosis d = TrackLostAndDiagnose(dim, map().camera);
  EXPECT_EQ(d.cause, LossCause::kTooDark) << d.detail;
  EXPECT_NE(d.detail.find("in the map's keyframes"), std::string::npos) << d.detail;
  // Without the keyframes' images the absolute floor still calls it dark.
  const ImageStats stats = MeasureImage(dim);
  EXPECT_EQ(LossDiagnoser(map().camera, map().camera, {}).Classify(dim.size(), stats, {}).cause, LossCause::kTooDark);
}

TEST_F(LossDiagnosisTest, TheMappedViewSmearedByMotionIsBlurred) {
  // A sideways pan during the exposure: a 41-pixel horizontal line kernel.
  const cv::Mat kernel = cv::Mat::ones(1, 41, CV_32F) / 41.0f;
  cv::Mat smeared;
  cv::filter2D(RenderMappedView(), smeared, -1, kernel);
  const LossDiagnosis d = TrackLostAndDiagnose(smeared, map().camera);
  EXPECT_EQ(d.cause, LossCause::kBlurred) << d.detail;
  EXPECT_NE(d.detail.find("blur 0.7"), std::string::npos) << d.detail;
  // Without the keyframes' images the measure's own scale still calls it blurred.
  EXPECT_EQ(LossDiagnoser(map().camera, map().camera, {}).Classify(smeared.size(), MeasureImage(smeared), {}).cause,
            LossCause::kBlurred);
}

TEST_F(LossDiagnosisTest, TheMappedViewFromACameraOfAnotherSizeDiffers) {
  // The same lens at 800x600: the tracker refuses the frame; the cause names both sizes.
  const PlanarWorld larger(plane_->texture, ScaleCamera(TestCamera(), 800, 600), 0.0015);
  const LossDiagnosis d = TrackLostAndDiagnose(larger.Render(MappedView()), larger.camera());
  EXPECT_EQ(d.cause, LossCause::kCameraDiffers) << d.detail;
  EXPECT_EQ(d.detail, "frames 800x600, the map's camera 640x480");
}

TEST_F(LossDiagnosisTest, AFrameOfTheMapsSizeFromAnotherFocalLengthDiffers) {
  // A recording whose camera.yaml says another lens at the map's size (zoomed 1.5x): the frame
  // itself looks fine; its camera's numbers say why.
  calib::Camera zoomed = TestCamera();
  zoomed.fx *= 1.5;
  zoomed.fy *= 1.5;
  const cv::Mat frame = PlanarWorld(plane_->texture, zoomed, 0.0015).Render(MappedView());
  const LossDiagnoser diagnoser(map().camera, zoomed, reference_);
  FrameResult lost;
  lost.relocalization_failure = PoseFailure::kTooFewInliers;
  const LossDiagnosis d = diagnoser.Diagnose(frame, lost);
  EXPECT_EQ(d.cause, LossCause::kCameraDiffers) << d.detail;
  EXPECT_EQ(d.detail, "focal length 780 px, the map's 520 px");
  // The same frame from the map's own camera is not blamed on the camera.
  EXPECT_NE(LossDiagnoser(map().camera, map().camera, reference_).Diagnose(frame, lost).cause, LossCause::kCameraDiffers);
}

TEST_F(LossDiagnosisTest, ABrightSharpViewWhoseMatchesAgreeOnNoPoseIsNotCalledOutsideTheMap) {
  // The solver's verdict decides between the two causes of a good-looking frame: too few matches
  // (outside the map), or enough that did not agree (degenerate, not refined, RMS too high).
  const cv::Mat view = RenderMappedView();
  const LossDiagnoser diagnoser(map().camera, map().camera, reference_);
  FrameResult lost;
  lost.keypoints = 2000;
  lost.matches = 60;
  for (const PoseFailure failure : {PoseFailure::kDegenerate, PoseFailure::kRefinementFailed, PoseFailure::kRmsTooHigh}) {
    lost.relocalization_failure = failure;
    const LossDiagnosis d = diagnoser.Diagnose(view, lost);
    EXPECT_EQ(d.cause, LossCause::kNoConsistentPose) << ToString(failure);
    EXPECT_EQ(d.detail, "60 matches of 2000 keypoints, " + ToString(failure));
  }
  lost.relocalization_failure = PoseFailure::kTooFewInliers;
  EXPECT_EQ(diagnoser.Diagnose(view, lost).cause, LossCause::kOutsideMap);
}

TEST(LossSummary, GroupsByCauseMostFrequentFirstAndNamesTheMapsPicture) {
  LossSummary summary;
  EXPECT_TRUE(summary.Advice("room-map").empty());
  for (int i = 0; i < 9; ++i) summary.Add({LossCause::kOutsideMap, "3 matches of 900 keypoints"});
  for (int i = 0; i < 3; ++i) summary.Add({LossCause::kTooDark, "brightness 9 against 121 in the map's keyframes"});
  EXPECT_EQ(summary.lost(), 12u);
  EXPECT_EQ(summary.count(LossCause::kOutsideMap), 9u);
  const std::vector<std::string> advice = summary.Advice("room-map");
  ASSERT_EQ(advice.size(), 3u);
  EXPECT_EQ(advice[0], "lost 12 frames:");
  EXPECT_EQ(advice[1].rfind("9 with too few matches (e.g. 3 matches of 900 keypoints): the view is outside the mapped "
                            "area — see room-map/map.png",
                            0),
            0u)
      << advice[1];
  EXPECT_EQ(advice[2].rfind("3 too dark (e.g. brightness 9 against 121", 0), 0u) << advice[2];
  EXPECT_EQ(LossHeadline({LossCause::kBlurred, "blur 0.78 against 0.34 in the map's keyframes"}),
            "motion blur (blur 0.78 against 0.34 in the map's keyframes)");
}

}  // namespace
}  // namespace arview::tracker
