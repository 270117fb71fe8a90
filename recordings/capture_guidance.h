#pragma once
// Capture guidance while recording (`arview record`, issue 56): whether the footage is likely to
// map, judged frame by frame as it comes, as Polycam's and Luma's capture guidance does. Each
// frame is looked at small (CaptureGuidanceOptions::working_width): its corners (FAST), its
// brightness, and points followed from the frame before (Lucas-Kanade) give
//
// - too few features: fewer corners than a map needs (a blank wall, a floor without texture);
// - too fast: the picture moves so fast that a frame's exposure smears it (motion blur);
// - too little parallax: whenever the picture has moved on by a share of its width since the
//   last view kept (a new "view"), the points followed between the two views are fitted with one
//   homography; a camera turning on the spot moves every point exactly as a homography does (as
//   does a flat wall seen from anywhere), a camera walking past things at several depths does
//   not. COLMAP needs the second: the share of points off that homography is the parallax;
// - too dark or too bright: too few features, and the mean grey level or the share of clipped
//   pixels says why;
// - coverage so far: the views kept, and how many of the steps between them had parallax.
//
// The end's verdict (`Summary`) says whether the recording is likely to map and why not.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/option_check.h"

namespace arview::recordings {

struct CaptureGuidanceOptions {
  // Frames are analysed at this width (aspect kept): the thresholds below are in its pixels.
  int working_width = 320;
  // FAST corners (threshold 20 grey levels: sensor noise of a few levels makes none) below which
  // a frame has too few features. A textured room gives hundreds at 320 wide.
  int min_corners = 80;
  double fast_threshold = 20;
  // The exposure of a webcam in a lit room: the picture's speed times it is the smear.
  double exposure_s = 1.0 / 60;
  // Smear (working pixels) beyond which a frame is too fast: 6 px at 320 wide (12 at 640, where
  // the tracker's blur measure reads a frame as smeared), a speed of 1.1 image widths a second.
  // The demo's walk peaks at 0.9 (docs/recordings.md, "Capture guidance").
  double max_smear_px = 6.0;
  // A new view is kept when the points followed moved by this share of the width since the last.
  double view_shift = 0.12;
  // A point is off the homography beyond this (working pixels), and a step between views has
  // parallax when at least this share of its points are.
  double parallax_px = 1.0;
  double parallax_share = 0.15;
  // Badly exposed: a frame with too few features whose mean grey level is below dark_mean, or
  // above bright_mean, or with more than clipped_share of its pixels at 250 or above. A dark
  // background round a lit, textured object (templeRing) has its features: not flagged.
  double dark_mean = 40, bright_mean = 215, clipped_share = 0.3;
  // At most this many frames a second are looked at (a frame sooner after the last one looked at
  // is skipped), so that at 30 fps the guidance takes half the time it would beside the frames'
  // writing; Lucas-Kanade's pyramid follows points over two frames' motion as over one.
  double max_rate_hz = 15;
  // How long a condition must last (seconds) before a note is said about it.
  double note_after_s = 1.0;
  // The verdict: a recording is unlikely to map when more than this share of its frames had too
  // few features, were too fast, or badly exposed; when fewer than min_parallax_share of the steps
  // between views had parallax, or fewer than min_views views were kept.
  double max_bad_share = 0.3;
  double min_parallax_share = 0.4;
  int min_views = 4;

  // Throws OptionError naming the first bad field.
  void Check(const OptionNames& names = {}) const;
};

// What one frame showed.
struct FrameGuidance {
  double time = 0;
  int corners = 0;
  double speed_px_s = 0;   // median speed of the points followed (working pixels a second)
  double smear_px = 0;     // speed x exposure
  double mean_grey = 0;
  double clipped = 0;      // share of pixels clipped white (250 or above)
  bool few_features = false, too_fast = false, too_dark = false, too_bright = false;
  bool new_view = false;   // a view was kept at this frame
  double parallax = -1;    // at a new view: the share of points off the homography; -1 otherwise
  std::vector<cv::Point2f> points;  // the points followed, in the frame's own pixels (to draw)
};

// A condition that lasted note_after_s, said once when it starts.
struct GuidanceNote {
  double time = 0;
  std::string text;  // "too fast: the picture smears (motion blur); move the camera slower"
};

struct GuidanceSummary {
  int frames = 0;  // looked at
  int views = 0;
  int steps = 0, steps_with_parallax = 0;  // steps between consecutive views
  int few_features = 0, too_fast = 0, badly_exposed = 0;  // frames
  bool likely_to_map = true;
  std::vector<std::string> reasons;  // why not, most important first; each with what to do
  // "likely to map: 14 views, 12 of 13 steps between them with parallax, ..." or
  // "unlikely to map: too little parallax (...); ..."
  std::string Line() const;
};

class CaptureGuidance {
 public:
  explicit CaptureGuidance(const CaptureGuidanceOptions& options = {});

  // Looks at the next frame (BGR or grey, any size; `time` in seconds, increasing); one that
  // comes sooner than 1 / max_rate_hz after the last one looked at is skipped (no notes).
  const FrameGuidance& Add(const cv::Mat& image, double time);
  // The notes said at the last frame (conditions that have just lasted note_after_s).
  const std::vector<GuidanceNote>& NewNotes() const { return new_notes_; }
  // What to do now, for the window: the most important condition of the last frames, or "".
  std::string Advice() const;
  GuidanceSummary Summary() const;
  const FrameGuidance& last() const { return last_; }
  // The steps between views so far, and those with parallax (the window's coverage line).
  int steps() const { return counts_.steps; }
  int steps_with_parallax() const { return counts_.steps_with_parallax; }
  int views() const { return counts_.views; }

 private:
  enum Condition { kFewFeatures, kTooFast, kNoParallax, kDark, kBright, kConditionCount };
  void FollowPoints(const cv::Mat& gray, FrameGuidance& frame);
  void KeepView(const cv::Mat& gray, FrameGuidance& frame);
  void UpdateConditions(const FrameGuidance& frame);

  CaptureGuidanceOptions options_;
  double scale_ = 1;  // working pixels per frame pixel
  cv::Mat previous_gray_;
  double previous_time_ = 0;
  std::vector<cv::Point2f> tracked_;       // in the previous frame
  std::vector<cv::Point2f> at_view_;       // the same points where the last view saw them
  FrameGuidance last_;
  GuidanceSummary counts_;  // the counts so far; Summary() adds the verdict
  bool last_step_flat_ = false;  // the last step between views had no parallax
  int flat_steps_in_a_row_ = 0;
  double since_[kConditionCount];  // when each condition started (-1: not on)
  bool said_[kConditionCount];
  std::vector<GuidanceNote> new_notes_;
};

}  // namespace arview::recordings
