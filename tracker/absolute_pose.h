#pragma once
// The pose solver on 2D-3D correspondences: bearings from the calibrated camera, OpenGV RANSAC
// (P3P KNEIP / GAO or EPnP), Ceres refinement on the inliers, then verification. A pose is
// returned only when it was verified; otherwise the failure says why.

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "base/option_check.h"
#include "calib/camera.h"
#include "calib/pose.h"
#include "tracker/ransac_p3p.h"
#include "tracker/refine_pose.h"

namespace arview::tracker {

struct AbsolutePoseOptions {
  MinimalSolver solver = MinimalSolver::kKneip;
  double ransac_threshold_px = 4.0;  // converted to OpenGV's 1 − cos(angle) with the mean focal
  int ransac_max_iterations = 1000;
  double ransac_success_probability = 0.999;
  std::uint32_t seed = 0;
  bool refine = true;
  RefineOptions refinement;
  // With a prior (tracking), RANSAC is skipped: the pose is refined from the prior over all
  // correspondences with a wide robust loss (prior_loss_scale_px), then on the inliers found.
  std::optional<calib::Pose> prior;
  double prior_loss_scale_px = 8.0;
  // After refinement, a correspondence is an inlier when its reprojection error is below this.
  double inlier_threshold_px = 4.0;
  // Acceptance: a pose is reported only with at least this many inliers and an inlier RMS
  // below max_rms_px.
  int min_inliers = 12;
  double max_rms_px = 2.5;
  // Inlier world points whose second principal extent is below this fraction of the first lie
  // on a line: rotation about that line is unobservable.
  double min_collinearity_ratio = 0.02;

  // Throws OptionError naming the first bad field (base/option_check.h; tracker/tracker_options.cpp).
  void Check(const OptionNames& names = {}) const;
};

enum class PoseFailure {
  kNone,
  kTooFewCorrespondences,
  kRansacFailed,
  kTooFewInliers,
  kDegenerate,
  kRefinementFailed,
  kRmsTooHigh,
};
constexpr auto EnumNames(PoseFailure) {
  return EnumTable<PoseFailure, 7>{{{PoseFailure::kNone, "none"},
                                    {PoseFailure::kTooFewCorrespondences, "too_few_correspondences"},
                                    {PoseFailure::kRansacFailed, "ransac_failed"},
                                    {PoseFailure::kTooFewInliers, "too_few_inliers"},
                                    {PoseFailure::kDegenerate, "degenerate"},
                                    {PoseFailure::kRefinementFailed, "refinement_failed"},
                                    {PoseFailure::kRmsTooHigh, "rms_too_high"}}};
}

struct AbsolutePoseStats {
  int correspondences = 0;
  int ransac_iterations = 0;
  int ransac_inliers = 0;
  int refine_iterations = 0;
  int inliers = 0;          // final, after refinement
  double rms_px = 0;        // over the final inliers
  double ransac_ms = 0;
  double refine_ms = 0;
};

struct AbsolutePoseResult {
  bool ok = false;
  PoseFailure failure = PoseFailure::kNone;
  std::string reason;          // human-readable when !ok
  calib::Pose pose;            // world → camera; meaningful only when ok
  std::vector<int> inliers;    // indices into the input correspondences
  AbsolutePoseStats stats;
};

// pixels: distorted pixels (OpenCV convention); points: world points, same order.
AbsolutePoseResult EstimateAbsolutePose(const calib::Camera& camera,
                                        const std::vector<Eigen::Vector2d>& pixels,
                                        const std::vector<Eigen::Vector3d>& points,
                                        const AbsolutePoseOptions& options);

// Second / first principal standard deviation of a point set (0 for fewer than two points).
double CollinearityRatio(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& subset);

}  // namespace arview::tracker
