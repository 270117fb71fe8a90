#include "tracker/loss_diagnosis.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>

#include "base/stats.h"
#include "tracker/features.h"

namespace arview::tracker {

namespace {

// Crete et al.'s no-reference blur (2007) along one axis of `grey` (CV_32F): the share of the
// image's neighbour differences that blurring it again with a 9-pixel box along that axis does
// not remove. A sharp image loses much of its variation when blurred (~0.2-0.4); an image
// already blurred along the axis loses little (towards 1), whatever it shows.
double ReblurAlong(const cv::Mat& grey, bool horizontal) {
  cv::Mat reblurred;
  cv::blur(grey, reblurred, horizontal ? cv::Size(9, 1) : cv::Size(1, 9));
  const cv::Mat kernel = horizontal ? (cv::Mat_<float>(1, 2) << -1, 1) : (cv::Mat_<float>(2, 1) << -1, 1);
  cv::Mat d_image, d_reblurred;
  cv::filter2D(grey, d_image, CV_32F, kernel);
  cv::filter2D(reblurred, d_reblurred, CV_32F, kernel);
  d_image = cv::abs(d_image);
  d_reblurred = cv::abs(d_reblurred);
  cv::Mat lost_variation = cv::max(d_image - d_reblurred, 0.0);
  const double variation = cv::sum(d_image)[0];
  return variation > 0 ? (variation - cv::sum(lost_variation)[0]) / variation : 1.0;
}

}  // namespace

ImageStats MeasureImage(const cv::Mat& image) {
  if (image.empty()) return {};
  cv::Mat grey = ToGray8(image);
  if (grey.cols > 640) {
    cv::resize(grey, grey, cv::Size(640, std::max(1, grey.rows * 640 / grey.cols)), 0, 0, cv::INTER_AREA);
  }
  cv::Mat grey_float;
  grey.convertTo(grey_float, CV_32F);
  return {cv::mean(grey)[0], std::max(ReblurAlong(grey_float, true), ReblurAlong(grey_float, false))};
}

AppearanceReference ReferenceFromImages(std::span<const cv::Mat> images) {
  std::vector<double> brightness, blur;
  for (const cv::Mat& image : images) {
    if (image.empty()) continue;
    const ImageStats s = MeasureImage(image);
    brightness.push_back(s.brightness);
    blur.push_back(s.blur);
  }
  if (brightness.empty()) return {};
  return {Median(brightness), Median(blur), static_cast<int>(brightness.size())};
}

LossDiagnoser::LossDiagnoser(const calib::Camera& map_camera, const calib::Camera& frame_camera,
                             const AppearanceReference& reference, const LossThresholds& thresholds)
    : map_camera_(map_camera), frame_camera_(frame_camera), reference_(reference), thresholds_(thresholds) {}

namespace {

std::string Format(const char* format, auto... values) {
  char line[192];
  std::snprintf(line, sizeof line, format, values...);
  return line;
}

std::string SizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

bool RelativelyFar(double value, double reference, double tolerance) {
  return std::abs(value - reference) > tolerance * std::abs(reference);
}

// Relocalization found too little of the map to pose from: the frame shows something else.
bool TooFewMatches(PoseFailure failure) {
  return failure == PoseFailure::kNone || failure == PoseFailure::kTooFewCorrespondences ||
         failure == PoseFailure::kRansacFailed || failure == PoseFailure::kTooFewInliers;
}

}  // namespace

std::optional<std::string> LossDiagnoser::CameraDifference(cv::Size frame_size) const {
  if (frame_size != map_camera_.Size()) {
    return "frames " + SizeText(frame_size) + ", the map's camera " + SizeText(map_camera_.Size());
  }
  const double tolerance = thresholds_.camera_tolerance;
  const calib::Camera& f = frame_camera_;
  const calib::Camera& m = map_camera_;
  if (f.Size() != m.Size()) return "camera " + SizeText(f.Size()) + ", the map's " + SizeText(m.Size());
  if (RelativelyFar(f.fx, m.fx, tolerance) || RelativelyFar(f.fy, m.fy, tolerance)) {
    return Format("focal length %.0f px, the map's %.0f px", f.fx, m.fx);
  }
  if (std::abs(f.cx - m.cx) > tolerance * m.width || std::abs(f.cy - m.cy) > tolerance * m.height) {
    return Format("principal point (%.0f, %.0f), the map's (%.0f, %.0f)", f.cx, f.cy, m.cx, m.cy);
  }
  return std::nullopt;
}

LossDiagnosis LossDiagnoser::Diagnose(const cv::Mat& image, const FrameResult& lost) const {
  return Classify(image.size(), MeasureImage(image), lost);
}

LossDiagnosis LossDiagnoser::Classify(cv::Size frame_size, const ImageStats& stats, const FrameResult& lost) const {
  // The camera first: with the wrong intrinsics no frame poses, however good it looks.
  if (const auto difference = CameraDifference(frame_size)) return {LossCause::kCameraDiffers, *difference};
  const bool referenced = reference_.images > 0;
  // Dark before blurred: a frame of a few grey levels has little detail to measure.
  if (referenced ? stats.brightness < thresholds_.dark_ratio * reference_.brightness
                 : stats.brightness < thresholds_.dark_floor) {
    return {LossCause::kTooDark,
            referenced ? Format("brightness %.0f against %.0f in the map's keyframes", stats.brightness, reference_.brightness)
                       : Format("brightness %.0f of 255", stats.brightness)};
  }
  if (referenced ? stats.blur > reference_.blur + thresholds_.blur_margin : stats.blur > thresholds_.blur_floor) {
    return {LossCause::kBlurred, referenced ? Format("blur %.2f against %.2f in the map's keyframes", stats.blur, reference_.blur)
                                            : Format("blur %.2f, sharp frames 0.3-0.45", stats.blur)};
  }
  if (lost.awaiting_relocalization) return {LossCause::kRelocalizing, "the relocalization had not finished"};
  const std::string matched = Format("%d matches of %d keypoints", lost.matches, lost.keypoints);
  if (TooFewMatches(lost.relocalization_failure)) return {LossCause::kOutsideMap, matched};
  return {LossCause::kNoConsistentPose, matched + ", " + ToString(lost.relocalization_failure)};
}

void LossSummary::Add(const LossDiagnosis& diagnosis) {
  const auto i = static_cast<std::size_t>(diagnosis.cause);
  ++lost_;
  if (counts_[i]++ == 0) first_detail_[i] = diagnosis.detail;
}

std::string LossAdvice(LossCause cause, std::size_t count, const std::string& detail, const std::string& map_folder) {
  const std::string n = std::to_string(count) + " ";
  const std::string numbers = " (" + detail + ")";
  switch (cause) {
    case LossCause::kCameraDiffers:
      return n + "from a camera that differs from the map's" + numbers +
             ": use the camera and size the map was built with, or map the room with this camera";
    case LossCause::kTooDark:
      return n + "too dark" + numbers + ": light the room as when it was mapped, or give the camera a longer exposure";
    case LossCause::kBlurred:
      return n + "with motion blur" + numbers +
             ": move the camera more slowly, or give it more light for a shorter exposure";
    case LossCause::kOutsideMap:
      return n + "with too few matches" + numbers + ": the view is outside the mapped area — see " +
             (std::filesystem::path(map_folder) / "map.png").string() +
             " for what the map covers, and point the camera there (or map this part too)";
    case LossCause::kNoConsistentPose:
      return n + "matched the map but no pose agreed" + numbers +
             ": the view is repetitive or nearly flat, or the room changed since it was mapped — keep more of the "
             "mapped room in view";
    case LossCause::kRelocalizing:
      return n + "came while the relocalization ran in the background" + numbers +
             ": the session's first frames and those after a loss are shown with the video alone until it finishes";
  }
  return n + ToString(cause);
}

std::string LossHeadline(const LossDiagnosis& diagnosis) {
  constexpr std::array<const char*, kLossCauses> kWords = {"camera differs from the map's", "too dark", "motion blur",
                                                           "outside the mapped area", "no pose agreed",
                                                           "relocalizing"};
  return std::string(kWords[static_cast<std::size_t>(diagnosis.cause)]) + " (" + diagnosis.detail + ")";
}

std::vector<std::string> LossSummary::Advice(const std::string& map_folder) const {
  if (lost_ == 0) return {};
  std::vector<std::size_t> order(kLossCauses);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [this](std::size_t a, std::size_t b) { return counts_[a] > counts_[b]; });
  std::vector<std::string> lines = {"lost " + std::to_string(lost_) + (lost_ == 1 ? " frame:" : " frames:")};
  for (const std::size_t i : order) {
    if (counts_[i] == 0) continue;
    const std::string example = (counts_[i] > 1 ? "e.g. " : "") + first_detail_[i];
    lines.push_back(LossAdvice(static_cast<LossCause>(i), counts_[i], example, map_folder));
  }
  return lines;
}

}  // namespace arview::tracker
