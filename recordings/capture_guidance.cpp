#include "recordings/capture_guidance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "base/stats.h"

namespace arview::recordings {

namespace {

constexpr int kMaxPoints = 200;     // points followed between views
constexpr int kMinStepPoints = 20;  // fewer followed to the next view: no homography is fitted

// What each condition says, in the window and as a note.
const char* const kAdvice[] = {
    "too few features: a blank surface; point the camera at textured things",
    "too fast: the picture smears (motion blur); move the camera slower",
    "too little parallax: turning on the spot; walk sideways past things, do not turn where you stand",
    "too dark: turn a light on",
    "too bright: much of the picture is clipped white; turn away from the window or lamp",
};

std::string Percent(int part, int whole) {
  return std::to_string(whole > 0 ? static_cast<int>(std::lround(100.0 * part / whole)) : 0) + "%";
}

double MedianShift(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b) {
  std::vector<double> d(a.size());
  for (size_t i = 0; i < a.size(); ++i) d[i] = cv::norm(a[i] - b[i]);
  return d.empty() ? 0 : Median(d);
}

// The share of point pairs that the best homography between them leaves farther than
// `threshold`: zero for a camera turning on the spot (or a plane), more the more the points'
// depths differ and the camera moved.
double ShareOffHomography(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to, double threshold) {
  const cv::Mat h = cv::findHomography(from, to, cv::RANSAC, threshold);
  if (h.empty()) return 1;  // no homography explains them at all
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(from, mapped, h);
  int off = 0;
  for (size_t i = 0; i < from.size(); ++i) off += cv::norm(mapped[i] - to[i]) > threshold;
  return static_cast<double>(off) / static_cast<double>(from.size());
}

}  // namespace

void CaptureGuidanceOptions::Check(const OptionNames& names) const {
  RequireOption(working_width >= 64, names("working_width"), "at least 64", working_width);
  RequireOption(min_corners >= 0, names("min_corners"), "0 or more", min_corners);
  RequireOption(fast_threshold > 0, names("fast_threshold"), "positive", fast_threshold);
  RequireOption(exposure_s > 0 && exposure_s < 1, names("exposure_s"), "in (0, 1) seconds", exposure_s);
  RequireOption(max_smear_px > 0, names("max_smear_px"), "positive", max_smear_px);
  RequireOption(view_shift > 0 && view_shift < 1, names("view_shift"), "in (0, 1)", view_shift);
  RequireOption(parallax_px > 0, names("parallax_px"), "positive", parallax_px);
  RequireOption(parallax_share > 0 && parallax_share < 1, names("parallax_share"), "in (0, 1)", parallax_share);
  RequireOption(dark_mean >= 0 && dark_mean < bright_mean && bright_mean <= 255, names("dark_mean"),
                "below bright_mean, both in [0, 255]", dark_mean);
  RequireOption(clipped_share > 0 && clipped_share <= 1, names("clipped_share"), "in (0, 1]", clipped_share);
  RequireOption(max_rate_hz > 0, names("max_rate_hz"), "positive", max_rate_hz);
  RequireOption(note_after_s >= 0, names("note_after_s"), "0 or more", note_after_s);
  RequireOption(max_bad_share >= 0 && max_bad_share <= 1, names("max_bad_share"), "in [0, 1]", max_bad_share);
  RequireOption(min_parallax_share >= 0 && min_parallax_share <= 1, names("min_parallax_share"), "in [0, 1]",
                min_parallax_share);
  RequireOption(min_views >= 1, names("min_views"), "at least 1", min_views);
}

CaptureGuidance::CaptureGuidance(const CaptureGuidanceOptions& options) : options_(options) {
  options_.Check();
  std::fill(std::begin(since_), std::end(since_), -1.0);
  std::fill(std::begin(said_), std::end(said_), false);
}

const FrameGuidance& CaptureGuidance::Add(const cv::Mat& image, double time) {
  new_notes_.clear();
  if (counts_.frames > 0 && time - previous_time_ < 0.9 / options_.max_rate_hz) return last_;
  scale_ = static_cast<double>(options_.working_width) / image.cols;
  cv::Mat gray, small;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = image;
  }
  cv::resize(gray, small, {}, scale_, scale_, scale_ < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);

  FrameGuidance frame;
  frame.time = time;
  std::vector<cv::KeyPoint> corners;
  cv::FAST(small, corners, static_cast<int>(options_.fast_threshold), true);
  frame.corners = static_cast<int>(corners.size());
  frame.few_features = frame.corners < options_.min_corners;
  frame.mean_grey = cv::mean(small)[0];
  frame.clipped = cv::countNonZero(small >= 250) / static_cast<double>(small.total());
  frame.too_dark = frame.few_features && frame.mean_grey < options_.dark_mean;
  frame.too_bright = frame.few_features && (frame.mean_grey > options_.bright_mean || frame.clipped > options_.clipped_share);

  FollowPoints(small, frame);
  KeepView(small, frame);
  previous_gray_ = small;
  previous_time_ = time;

  ++counts_.frames;
  counts_.few_features += frame.few_features;
  counts_.too_fast += frame.too_fast;
  counts_.badly_exposed += frame.too_dark || frame.too_bright;
  UpdateConditions(frame);
  for (cv::Point2f& p : frame.points = tracked_) p *= static_cast<float>(1 / scale_);
  last_ = std::move(frame);
  return last_;
}

// The points of the last view followed into this frame; their median speed is the picture's.
void CaptureGuidance::FollowPoints(const cv::Mat& gray, FrameGuidance& frame) {
  if (previous_gray_.empty() || previous_gray_.size() != gray.size() || tracked_.empty()) return;
  std::vector<cv::Point2f> next;
  std::vector<uchar> found;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(previous_gray_, gray, tracked_, next, found, error, {21, 21}, 3);
  std::vector<cv::Point2f> kept_before, kept_now, kept_at_view;
  for (size_t i = 0; i < next.size(); ++i) {
    const bool inside = next[i].x >= 0 && next[i].y >= 0 && next[i].x < gray.cols && next[i].y < gray.rows;
    if (!found[i] || !inside) continue;
    kept_before.push_back(tracked_[i]);
    kept_now.push_back(next[i]);
    kept_at_view.push_back(at_view_[i]);
  }
  const double dt = frame.time - previous_time_;
  if (!kept_now.empty() && dt > 0) {
    frame.speed_px_s = MedianShift(kept_before, kept_now) / dt;
    frame.smear_px = frame.speed_px_s * options_.exposure_s;
    frame.too_fast = frame.smear_px > options_.max_smear_px;
  }
  tracked_ = std::move(kept_now);
  at_view_ = std::move(kept_at_view);
}

// A new view once the picture has moved on (or lost most of its points): the step from the last
// one is judged for parallax, and fresh points are picked to follow.
void CaptureGuidance::KeepView(const cv::Mat& gray, FrameGuidance& frame) {
  const bool first = counts_.views == 0;
  const bool moved_on = !at_view_.empty() && MedianShift(at_view_, tracked_) > options_.view_shift * gray.cols;
  const bool lost_most = static_cast<int>(tracked_.size()) < kMinStepPoints;
  if (!first && !moved_on && !lost_most) return;
  if (frame.few_features && !first && !moved_on) return;  // nothing new to keep on a blank surface
  if (!first && static_cast<int>(tracked_.size()) >= kMinStepPoints) {
    frame.parallax = ShareOffHomography(at_view_, tracked_, options_.parallax_px);
    ++counts_.steps;
    const bool flat = frame.parallax < options_.parallax_share;
    counts_.steps_with_parallax += !flat;
    flat_steps_in_a_row_ = flat ? flat_steps_in_a_row_ + 1 : 0;
  }
  std::vector<cv::Point2f> fresh;
  cv::goodFeaturesToTrack(gray, fresh, kMaxPoints, 0.01, 8);
  if (fresh.size() < static_cast<size_t>(kMinStepPoints) && !first) {
    // Not a view one could map from: keep following what is left.
    return;
  }
  ++counts_.views;
  frame.new_view = true;
  tracked_ = fresh;
  at_view_ = fresh;
}

void CaptureGuidance::UpdateConditions(const FrameGuidance& frame) {
  const bool on[kConditionCount] = {frame.few_features, frame.too_fast, flat_steps_in_a_row_ >= 2, frame.too_dark,
                                    frame.too_bright};
  for (int c = 0; c < kConditionCount; ++c) {
    if (!on[c]) {
      since_[c] = -1;
      said_[c] = false;
      continue;
    }
    if (since_[c] < 0) since_[c] = frame.time;
    if (!said_[c] && frame.time - since_[c] >= options_.note_after_s) {
      said_[c] = true;
      new_notes_.push_back({frame.time, kAdvice[c]});
    }
  }
}

std::string CaptureGuidance::Advice() const {
  for (int c : {kDark, kBright, kFewFeatures, kTooFast, kNoParallax}) {
    if (since_[c] >= 0) return kAdvice[c];
  }
  return "";
}

GuidanceSummary CaptureGuidance::Summary() const {
  GuidanceSummary s = counts_;
  const double bad = options_.max_bad_share * counts_.frames;
  if (counts_.badly_exposed > bad) {
    s.reasons.push_back("badly exposed in " + Percent(counts_.badly_exposed, counts_.frames) +
                        " of the frames (too dark or clipped white to find features in): light the room evenly");
  }
  if (counts_.few_features > bad) {
    s.reasons.push_back("too few features in " + Percent(counts_.few_features, counts_.frames) +
                        " of the frames (a blank wall or floor): film textured things");
  }
  if (counts_.too_fast > bad) {
    s.reasons.push_back("too fast in " + Percent(counts_.too_fast, counts_.frames) + " of the frames (motion blur): move slower");
  }
  if (counts_.steps > 0 && counts_.steps_with_parallax < options_.min_parallax_share * counts_.steps) {
    s.reasons.push_back("too little parallax: " + std::to_string(counts_.steps_with_parallax) + " of " +
                        std::to_string(counts_.steps) +
                        " steps between views moved the camera past things at other depths (turning on the spot?): "
                        "walk sideways through the room");
  }
  if (counts_.views < options_.min_views) {
    s.reasons.push_back("too little coverage: " + std::to_string(counts_.views) +
                        " view(s), the picture hardly changed: look at the room from several places");
  }
  s.likely_to_map = s.reasons.empty();
  return s;
}

std::string GuidanceSummary::Line() const {
  if (!likely_to_map) {
    std::string line = "unlikely to map: ";
    for (size_t i = 0; i < reasons.size(); ++i) line += (i ? "; " : "") + reasons[i];
    return line;
  }
  return "likely to map: " + std::to_string(views) + " views, " + std::to_string(steps_with_parallax) + " of " +
         std::to_string(steps) + " steps between them with parallax, " + Percent(too_fast, frames) + " of " +
         std::to_string(frames) + " frames looked at too fast, " + Percent(few_features, frames) + " with too few features";
}

}  // namespace arview::recordings
