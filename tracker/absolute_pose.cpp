#include "tracker/absolute_pose.h"

#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "tracker/timing.h"

namespace arview::tracker {
namespace {

AbsolutePoseResult Fail(AbsolutePoseResult result, PoseFailure failure, const std::string& reason) {
  result.ok = false;
  result.failure = failure;
  result.reason = reason;
  return result;
}

std::vector<int> SelectInliers(const calib::Camera& camera, const calib::Pose& pose,
                               const std::vector<Eigen::Vector2d>& pixels,
                               const std::vector<Eigen::Vector3d>& points, double threshold_px,
                               double* rms_px) {
  std::vector<int> inliers;
  double sum_sq = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const double e = ReprojectionError(camera, pose, pixels[i], points[i]);
    if (e < threshold_px) {
      inliers.push_back(static_cast<int>(i));
      sum_sq += e * e;
    }
  }
  *rms_px = inliers.empty() ? 0 : std::sqrt(sum_sq / inliers.size());
  return inliers;
}

// Marks `result` as degenerate when the subset's world points lie nearly on a line.
bool IsCollinear(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& subset,
                 const AbsolutePoseOptions& options, AbsolutePoseResult* result) {
  const double ratio = CollinearityRatio(points, subset);
  if (ratio >= options.min_collinearity_ratio) return false;
  std::ostringstream msg;
  msg << "inlier points are nearly collinear (extent ratio " << ratio << ")";
  *result = Fail(*result, PoseFailure::kDegenerate, msg.str());
  return true;
}

template <typename T>
std::vector<T> Gather(const std::vector<T>& values, const std::vector<int>& subset) {
  std::vector<T> out;
  out.reserve(subset.size());
  for (int i : subset) out.push_back(values[i]);
  return out;
}

}  // namespace

double CollinearityRatio(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& subset) {
  if (subset.size() < 2) return 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : subset) mean += points[i];
  mean /= static_cast<double>(subset.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : subset) cov += (points[i] - mean) * (points[i] - mean).transpose();
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues();
  if (ev(2) <= 0) return 0;
  return std::sqrt(std::max(ev(1), 0.0) / ev(2));  // eigenvalues ascend
}

AbsolutePoseResult EstimateAbsolutePose(const calib::Camera& camera,
                                        const std::vector<Eigen::Vector2d>& pixels,
                                        const std::vector<Eigen::Vector3d>& points,
                                        const AbsolutePoseOptions& options) {
  if (pixels.size() != points.size())
    throw Error("EstimateAbsolutePose: pixels and points differ in count");
  AbsolutePoseResult result;
  result.stats.correspondences = static_cast<int>(pixels.size());
  const int needed = std::max(options.min_inliers, MinimalSampleSize(options.solver));
  if (static_cast<int>(pixels.size()) < needed) {
    std::ostringstream msg;
    msg << pixels.size() << " correspondences, at least " << needed << " needed";
    return Fail(result, PoseFailure::kTooFewCorrespondences, msg.str());
  }

  // Checked before RANSAC too: on a line the minimal solvers fail and "RANSAC found no pose"
  // would hide the reason.
  std::vector<int> all(pixels.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  if (IsCollinear(points, all, options, &result)) return result;

  calib::Pose pose;
  std::vector<int> hypothesis;  // the correspondences the final refinement runs on
  if (options.prior) {
    // A wide robust refinement from the prior over every correspondence settles in the prior's
    // basin (P3P on a small, nearly planar patch may prefer the mirrored solution); the
    // correspondences it explains are then refined as RANSAC's inliers would be.
    const auto refine_start = std::chrono::steady_clock::now();
    RefineOptions wide = options.refinement;
    wide.loss_scale_px = options.prior_loss_scale_px;
    const RefineResult settled = RefinePose(camera, pixels, points, *options.prior, wide);
    result.stats.refine_ms += MillisecondsSince(refine_start);
    if (!settled.ok) return Fail(result, PoseFailure::kRefinementFailed, "pose refinement failed");
    double rms_unused = 0;
    hypothesis = SelectInliers(camera, settled.pose, pixels, points, options.inlier_threshold_px, &rms_unused);
    pose = settled.pose;
    if (static_cast<int>(hypothesis.size()) < options.min_inliers) {
      std::ostringstream msg;
      msg << hypothesis.size() << " inliers around the prior, at least " << options.min_inliers << " needed";
      return Fail(result, PoseFailure::kTooFewInliers, msg.str());
    }
  } else {
    const auto ransac_start = std::chrono::steady_clock::now();
    std::vector<Eigen::Vector3d> bearings;
    bearings.reserve(pixels.size());
    for (const auto& p : pixels) bearings.push_back(camera.Unproject(p));
    RansacOptions ransac_options;
    ransac_options.solver = options.solver;
    ransac_options.threshold =
        PixelThresholdToOpenGV(options.ransac_threshold_px, 0.5 * (camera.fx + camera.fy));
    ransac_options.max_iterations = options.ransac_max_iterations;
    ransac_options.success_probability = options.ransac_success_probability;
    ransac_options.seed = options.seed;
    const RansacResult ransac = RansacAbsolutePose(bearings, points, ransac_options);
    result.stats.ransac_ms = MillisecondsSince(ransac_start);
    result.stats.ransac_iterations = ransac.stats.iterations;
    result.stats.ransac_inliers = ransac.stats.inliers;
    if (!ransac.found) return Fail(result, PoseFailure::kRansacFailed, "RANSAC found no pose");
    if (ransac.stats.inliers < options.min_inliers) {
      std::ostringstream msg;
      msg << "RANSAC found " << ransac.stats.inliers << " inliers, at least " << options.min_inliers
          << " needed";
      return Fail(result, PoseFailure::kTooFewInliers, msg.str());
    }
    pose = ransac.pose;
    hypothesis = ransac.inliers;
  }
  if (IsCollinear(points, hypothesis, options, &result)) return result;

  if (options.refine) {
    const auto refine_start = std::chrono::steady_clock::now();
    const RefineResult refined = RefinePose(camera, Gather(pixels, hypothesis),
                                            Gather(points, hypothesis), pose, options.refinement);
    result.stats.refine_ms += MillisecondsSince(refine_start);
    result.stats.refine_iterations = refined.stats.iterations;
    if (!refined.ok) return Fail(result, PoseFailure::kRefinementFailed, "pose refinement failed");
    pose = refined.pose;
  }

  double rms = 0;
  result.inliers = SelectInliers(camera, pose, pixels, points, options.inlier_threshold_px, &rms);
  result.stats.inliers = static_cast<int>(result.inliers.size());
  result.stats.rms_px = rms;
  if (result.stats.inliers < options.min_inliers) {
    std::ostringstream msg;
    msg << result.stats.inliers << " inliers after refinement, at least " << options.min_inliers
        << " needed";
    return Fail(result, PoseFailure::kTooFewInliers, msg.str());
  }
  if (IsCollinear(points, result.inliers, options, &result)) return result;
  if (rms > options.max_rms_px) {
    std::ostringstream msg;
    msg << "inlier RMS " << rms << " px above " << options.max_rms_px << " px";
    return Fail(result, PoseFailure::kRmsTooHigh, msg.str());
  }
  result.pose = pose;
  result.ok = true;
  return result;
}

}  // namespace arview::tracker
