#pragma once
// Why a frame was lost, in words a user can act on. The tracker says what failed ("RANSAC found
// 4 inliers, at least 12 needed"); that is the symptom. The cause is in the frame's numbers set
// against the map's: a frame far darker than the map's keyframes, far less sharp, from a camera
// of another size or focal length, or bright and sharp but matching too little of the map (the
// view is outside the mapped area). `arview replay`, `run` and `track` count the lost frames by
// cause and turn the counts into advice (docs/tracker.md, "Why a frame was lost").

#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "base/enum_table.h"
#include "calib/camera.h"
#include "tracker/tracker.h"

namespace arview::tracker {

// Measured on a grey copy at most 640 px wide, so that the figures of frames of different sizes
// compare.
struct ImageStats {
  double brightness = 0;  // mean grey level, 0-255
  // 0 (sharp) to 1 (smeared): Crete et al.'s re-blur measure, the worse of the two axes. It
  // reads the image's own falloff of detail, so a smooth scene is not taken for a blurred one
  // (the variance of the Laplacian was: a sharp photo of fruit measured 15% of the graffiti's,
  // a 31-px smear of the graffiti 5%). Measured: sharp frames 0.32-0.43 (the graffiti, OpenCV's
  // sample photos, templeRing), smeared ones 0.70-0.80 (a 9- to 41-px smear of the graffiti,
  // a 20-px smear of templeRing's).
  double blur = 0;
};
ImageStats MeasureImage(const cv::Mat& image);

// What the frames the map was built from look like: the medians over some of its keyframes'
// images. images == 0: none could be read; then the frame's figures are judged on fixed floors.
struct AppearanceReference {
  double brightness = 0;
  double blur = 0;
  int images = 0;
};
AppearanceReference ReferenceFromImages(std::span<const cv::Mat> images);

// kRelocalizing: a live session's frame that came while the relocalization ran on the tracker's
// worker (TrackingOptions::background): it was not tried against the map.
enum class LossCause { kCameraDiffers, kTooDark, kBlurred, kOutsideMap, kNoConsistentPose, kRelocalizing };
constexpr auto EnumNames(LossCause) {
  return EnumTable<LossCause, 6>{{{LossCause::kCameraDiffers, "camera_differs"},
                                  {LossCause::kTooDark, "too_dark"},
                                  {LossCause::kBlurred, "blurred"},
                                  {LossCause::kOutsideMap, "outside_map"},
                                  {LossCause::kNoConsistentPose, "no_consistent_pose"},
                                  {LossCause::kRelocalizing, "relocalizing"}}};
}
inline constexpr std::size_t kLossCauses = 6;

struct LossDiagnosis {
  LossCause cause = LossCause::kOutsideMap;
  std::string detail;  // the numbers behind it: "brightness 9 against 121 in the map's keyframes"
};

struct LossThresholds {
  // Darker than this fraction of the keyframes' median brightness. SIFT's contrast threshold is
  // absolute: on the graffiti plane of loss_diagnosis_test.cpp (keyframes 109) the mapped view
  // still relocalized at 14 (13%) and was lost at 9 (8.5%).
  double dark_ratio = 0.25;
  double dark_floor = 20;  // without keyframe images: a mean grey level below this is dark
  // More blurred than the keyframes' median by this much (ImageStats::blur), or without
  // keyframe images above blur_floor. On the graffiti plane (keyframes 0.34) the mapped view was
  // lost from a 31-px smear on; a 9-px smear already reads 0.70.
  double blur_margin = 0.2;
  double blur_floor = 0.6;
  // The frame's camera differs from the map's when a focal length or the principal point is
  // off by more than this fraction (of the focal length; of the image's width or height).
  double camera_tolerance = 0.02;
};

class LossDiagnoser {
 public:
  // `frame_camera`: the camera the frames come from (a recording's camera.yaml; for a live
  // camera, the map's camera scaled to its size). A caller that tracks the frames with their own
  // camera (Tracker(map, camera, options): app's sessions and `track`) passes that camera as
  // both, since then the camera is no cause of a lost frame.
  LossDiagnoser(const calib::Camera& map_camera, const calib::Camera& frame_camera, const AppearanceReference& reference,
                const LossThresholds& thresholds = {});
  // The cause of a lost frame, from its image and the tracker's result.
  LossDiagnosis Diagnose(const cv::Mat& image, const FrameResult& lost) const;
  // The same from the numbers alone: the frame's size and statistics, the tracker's result.
  LossDiagnosis Classify(cv::Size frame_size, const ImageStats& stats, const FrameResult& lost) const;
  const AppearanceReference& reference() const { return reference_; }
  // How frames of `frame_size` from the frame camera differ from the map's camera; nothing when
  // they do not (a session says it before the first frame).
  std::optional<std::string> CameraDifference(cv::Size frame_size) const;

 private:
  calib::Camera map_camera_;
  calib::Camera frame_camera_;
  AppearanceReference reference_;
  LossThresholds thresholds_;
};

// The lost frames of a session counted by cause, in constant memory: one example detail per
// cause (the first seen) and the counts.
class LossSummary {
 public:
  void Add(const LossDiagnosis& diagnosis);
  std::size_t lost() const { return lost_; }
  std::size_t count(LossCause cause) const { return counts_[static_cast<std::size_t>(cause)]; }
  // "lost 12 frames, 9 with too few matches: the view is outside the mapped area ..." then one
  // line per further cause, most frequent first; empty when no frame was lost. `map_folder`
  // names the map (its map.png) in the advice.
  std::vector<std::string> Advice(const std::string& map_folder) const;

 private:
  std::size_t lost_ = 0;
  std::array<std::size_t, kLossCauses> counts_{};
  std::array<std::string, kLossCauses> first_detail_;
};

// One line of advice for `count` frames lost to `cause` (what LossSummary::Advice says per
// cause; the HUD's line for the frame being lost with count 1 and its detail).
std::string LossAdvice(LossCause cause, std::size_t count, const std::string& detail, const std::string& map_folder);
// The few words the HUD shows while a frame is lost: "too dark (brightness 9 against 121 in the
// map's keyframes)".
std::string LossHeadline(const LossDiagnosis& diagnosis);

}  // namespace arview::tracker
