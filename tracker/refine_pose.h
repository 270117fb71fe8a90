#pragma once
// Non-linear refinement of a camera pose on 2D-3D correspondences: reprojection error in pixels
// through the full camera model (distortion included), a robust loss (Ceres' definitions), by
// Levenberg-Marquardt with analytic Jacobians on a rotation increment and the translation.

#include <Eigen/Core>

#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::tracker {

enum class RobustLoss { kNone, kHuber, kCauchy };

struct RefineOptions {
  RobustLoss loss = RobustLoss::kCauchy;
  double loss_scale_px = 2.0;  // residual (pixels) where the robust loss starts to bend
  int max_iterations = 20;       // Levenberg-Marquardt steps tried
  double function_tolerance = 1e-8;  // converged below this relative decrease of the cost
};

struct RefineStats {
  int iterations = 0;
  double initial_cost = 0;
  double final_cost = 0;
  bool converged = false;
};

struct RefineResult {
  bool ok = false;  // false for empty or mismatched input, or a non-finite pose
  calib::Pose pose;
  RefineStats stats;
};

// pixels: observed distorted pixels (OpenCV convention); points: world points, same order.
RefineResult RefinePose(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                        const std::vector<Eigen::Vector3d>& points, const calib::Pose& initial,
                        const RefineOptions& options);

// Pixel reprojection error of one correspondence; +inf when the point is behind the camera.
double ReprojectionError(const calib::Camera& camera, const calib::Pose& pose,
                         const Eigen::Vector2d& pixel, const Eigen::Vector3d& point);

}  // namespace arview::tracker
