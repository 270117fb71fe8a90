#pragma once
// Trajectory accuracy: association by timestamp, Umeyama Sim(3)/SE(3) alignment, absolute
// trajectory error (camera centres), rotation error, relative pose error, coverage.
//
// Typical use from a test (the honest protocol for localization: the alignment is fitted on
// the map's keyframe poses, never on the query frames being judged):
//
//   AccuracyOptions opt;
//   opt.align = AlignMode::kSim3;
//   opt.align_with = &keyframe_poses;          // optional; default: fit on the estimate itself
//   const AccuracyReport r = EvaluateTrajectory(estimate, groundtruth, opt);
//   EXPECT_LT(r.ate.median, 0.002);
//
// Every function throws RecordingError on input it cannot judge (too few associated poses,
// degenerate point sets), never returns a silent number.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "base/enum_table.h"
#include "base/geometry.h"
#include "base/stats.h"
#include "recordings/trajectory.h"

namespace arview::recordings {

// x ↦ scale · R · x + t, maps positions of one trajectory's world into another's: base/'s.
using Sim3 = arview::Sim3;
// The same camera expressed in the target world: centre mapped, orientation rotated by R.
calib::Pose Transform(const Sim3& transform, const calib::Pose& pose);

enum class AlignMode { kNone, kSE3, kSim3 };
constexpr auto EnumNames(AlignMode) {
  return EnumTable<AlignMode, 3>{{{AlignMode::kNone, "none"}, {AlignMode::kSE3, "se3"}, {AlignMode::kSim3, "sim3"}}};
}
// "none" | "se3" | "sim3"; RecordingError otherwise. (Back: arview::ToString.)
AlignMode ParseAlignMode(const std::string& text);

// Least-squares similarity (with_scale) or rigid motion mapping src[i] onto dst[i]
// (arview::EstimateSim3, i.e. Eigen::umeyama). Needs at least 3 points not all on one line;
// throws RecordingError otherwise.
Sim3 Umeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, bool with_scale);

// Pairs (index into a, index into b) whose timestamps differ by at most max_dt seconds; each
// pose is used at most once, closest pairs first (as TUM's associate.py, but considering only
// the 4 nearest poses of b on either side of each pose of a). Sorted by a's time.
std::vector<std::pair<size_t, size_t>> AssociateByTimestamp(const Trajectory& a, const Trajectory& b,
                                                            double max_dt);

// The alignment that maps `from`'s world onto `to`'s, fitted on camera centres of the poses
// associated by timestamp. kNone gives the identity (and needs no association).
Sim3 FitAlignment(const Trajectory& from, const Trajectory& to, AlignMode mode, double max_dt);

Trajectory TransformTrajectory(const Trajectory& trajectory, const Sim3& transform);

// Throws RecordingError("<what>: the pose at <t> s is at (x, y, z), beyond 1e+100 of the origin")
// unless every camera centre is finite and within kMaxPositionNorm (base/point_spread.h): beyond
// it the errors' squares overflow (a centre at 8.7e306 with --align none gave an ATE of inf).
void RequirePositionsInRange(const Trajectory& trajectory, const std::string& what);

// rmse, mean, median, max, count (and percentiles) by base/stats.h's one definition.
using ErrorStats = arview::Summary;

struct AccuracyOptions {
  AlignMode align = AlignMode::kSim3;
  double max_dt = 0.02;                     // association tolerance, seconds
  int rpe_delta = 1;                        // RPE over pairs (k, k + delta) of associated poses
  const Trajectory* align_with = nullptr;   // fit the alignment on this trajectory instead
};

struct AccuracyReport {
  AlignMode align = AlignMode::kSim3;
  bool aligned_with_other = false;
  Sim3 alignment;              // estimate world → ground-truth world
  int estimate_poses = 0;
  int groundtruth_poses = 0;
  int associated = 0;          // estimate poses paired with a ground-truth pose
  int alignment_pairs = 0;     // pairs the alignment was fitted on
  double coverage = 0;         // associated / groundtruth_poses
  ErrorStats ate;              // camera-centre error after alignment (ground-truth units)
  ErrorStats rotation_deg;     // angle between aligned and true orientations, degrees
  int rpe_delta = 1;
  ErrorStats rpe_translation;  // relative motion error over rpe_delta steps (ground-truth units)
  ErrorStats rpe_rotation_deg;
  // Per associated pair, in estimate-time order: (estimate index, ground-truth index) and errors.
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<double> position_errors;
  std::vector<double> rotation_errors_deg;
  Trajectory aligned_estimate;  // the whole estimate mapped into the ground-truth world
};

AccuracyReport EvaluateTrajectory(const Trajectory& estimate, const Trajectory& groundtruth,
                                  const AccuracyOptions& options = {});

// Angle of the rotation between two orientations, degrees.
double RotationErrorDeg(const calib::Pose& a, const calib::Pose& b);

// Machine-readable summary (one JSON object; no per-pose arrays).
std::string ReportToJson(const AccuracyReport& report);
// Human-readable summary, several lines.
std::string ReportToText(const AccuracyReport& report);

// A PNG with a top view and a side view (the ground-truth path's principal plane and a plane
// across it) of the ground truth (grey) and the aligned estimate, each estimate position
// coloured by its error (colour bar in the image). Throws arview::Error naming the file if it
// cannot write it.
void PlotTrajectories(const AccuracyReport& report, const Trajectory& groundtruth,
                      const std::filesystem::path& png, int width = 1200, int height = 600);

}  // namespace arview::recordings
