#pragma once
// Registration as the viewer sees it (issue 58): how far, in pixels, the estimated pose puts
// points of the scene (a character's anchor, its bounding box's corners) from where the true
// pose puts them; how much the anchor shivers on a still camera; how much the smoothing lags
// behind the raw centre while moving; and recall at 1 cm/1°, 2 cm/2°, 5 cm/5°.
//
//   const AccuracyReport accuracy = EvaluateTrajectory(estimate, groundtruth, options);
//   RegistrationOptions reg;
//   reg.points = {anchor, corner0, ...};         // in the estimate's world (the map's)
//   reg.smoothed = &smoothed_centres;            // optional: the One Euro centres of the frames
//   const RegistrationReport r = EvaluateRegistration(accuracy, estimate, groundtruth, camera, reg);
//
// The points are mapped into the ground truth's world by the accuracy report's alignment and
// projected there with the aligned estimate and the true pose; a similarity changes no
// projection, so the error is the one the estimate made in the map. Without points only the
// recall and the lag are computed (and the ground-truth geometry's error, when given). Throws RecordingError on input it cannot judge (points but no
// frame with one in front of both cameras).

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera.h"
#include "recordings/accuracy.h"

namespace arview::recordings {

// A camera centre at a time: the tracker's One Euro-smoothed centre of a frame (stats.json's
// `smoothed_center`), in the estimate's world.
struct StampedCentre {
  double timestamp = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

struct RegistrationOptions {
  std::vector<Eigen::Vector3d> points;  // estimate's world; points[0] is the anchor
  // Points of the scene's true geometry, in the ground truth's world (a rendered room's
  // surfaces): each frame is scored on those its true camera sees in the image, as DCRE
  // (Brachmann et al. 2021) scores a frame's own depth points.
  std::vector<Eigen::Vector3d> groundtruth_points;
  double over_px = 5.0;                 // the share of frames over this error is reported
  double trend_window_s = 1.0;          // jitter: the anchor's projection less its mean over this window
  double min_still_s = 1.0;             // a still segment of the ground truth at least this long is judged
  const std::vector<StampedCentre>* smoothed = nullptr;  // optional: lag, and the smoothed centre's jitter
  double max_lag_s = 0.5;               // the lag is searched within ±this
};

// A stretch where the true camera does not move (a tripod), and the anchor's jitter there.
struct StillSegment {
  double start_s = 0, end_s = 0;  // timestamps of its first and last frame
  int frames = 0;                 // its frames with an estimate
  double anchor_distance = 0;     // from the true camera to the anchor, ground-truth units
  // The anchor's projection with the estimated pose (the raw R, t the renderer draws the
  // character with), less its mean over the trend window: RMS of the 2-D residual.
  double jitter_px = 0;
  double jitter_arcmin = 0;       // jitter_px over the focal length, as an angle
  double jitter_mm = 0;           // that angle at the anchor's distance (ground truth in metres)
  // The same with the smoothed centre in place of the raw one (the animation's viewpoint);
  // set only when smoothed centres were given.
  std::optional<double> smoothed_jitter_px;
};

struct RecallAt {
  double metres = 0, degrees = 0;
  double recall = 0;  // share of the ground-truth poses in the estimate's time span within both
};

struct RegistrationReport {
  int points = 0;
  int frames = 0;                  // associated frames with a point in front of both cameras
  ErrorStats frame_mean_px;        // per frame: the mean error over the points (as DCRE)
  ErrorStats frame_max_px;         // per frame: the worst point
  double over_px = 5.0;
  double share_over = 0;           // frames whose worst point is over over_px
  // The anchor's error vector less its mean over the trend window, RMS, over the frames outside
  // still segments: the part of the error faster than the window (the moving camera's jitter).
  std::optional<double> fast_error_px;
  int geometry_frames = 0;         // frames with a ground-truth point in the true image
  ErrorStats geometry_mean_px;     // per frame: the mean error over those points
  std::vector<StillSegment> stills;
  // The shift of the raw centres that best matches the smoothed ones (least squares over the
  // moving frames, the cross-correlation's peak), in frames of the median frame interval;
  // positive: the smoothed centre lags. Set only with smoothed centres.
  std::optional<double> lag_frames;
  int lag_samples = 0;
  int judged_groundtruth = 0;      // ground-truth poses within the estimate's time span
  std::vector<RecallAt> recall;
  std::vector<double> per_frame_mean_px;  // in estimate-time order, for plots and tests
};

RegistrationReport EvaluateRegistration(const AccuracyReport& accuracy, const Trajectory& estimate,
                                        const Trajectory& groundtruth, const calib::Camera& camera,
                                        const RegistrationOptions& options);

// Recall at each (metres, degrees) pair: the share of the ground-truth poses in the estimate's
// time span whose estimate is within both (a lost frame counts as a miss).
std::vector<RecallAt> Recall(const AccuracyReport& accuracy, const Trajectory& groundtruth,
                             const std::vector<std::pair<double, double>>& thresholds);

// Each position less the mean of the positions within ±window/2 of its time; only samples
// whose window lies wholly inside [times.front(), times.back()] are returned.
std::vector<Eigen::Vector2d> RemoveTrend(const std::vector<double>& times, const std::vector<Eigen::Vector2d>& values,
                                         double window_s);

// The time shift τ (seconds, within ±max_shift_s) minimising Σ |smoothed(t) − raw(t − τ)|²,
// raw linearly interpolated; nullopt when fewer than 10 samples overlap at every shift.
std::optional<double> LagSeconds(const std::vector<StampedCentre>& raw, const std::vector<StampedCentre>& smoothed,
                                 double max_shift_s, int* samples = nullptr);

// `arview eval`'s additions: a JSON object (the value of its "registration" key) and text lines.
std::string RegistrationToJson(const RegistrationReport& report);
std::string RegistrationToText(const RegistrationReport& report);

}  // namespace arview::recordings
