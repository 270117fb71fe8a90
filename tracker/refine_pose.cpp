#include "tracker/refine_pose.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <limits>
#include <memory>

namespace arview::tracker {
namespace {

struct ReprojectionCost {
  ReprojectionCost(const calib::Camera& camera, const Eigen::Vector2d& pixel,
                   const Eigen::Vector3d& point)
      : camera_(camera), pixel_(pixel), point_(point) {}

  template <typename T>
  bool operator()(const T* q_xyzw, const T* t, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_xyzw);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t);
    const Eigen::Matrix<T, 3, 1> p = q * point_.cast<T>() + translation;
    // Behind-camera points have no meaningful projection; a large constant residual keeps the
    // robust loss from pulling the solution through the image plane.
    if (p.z() <= T(1e-9)) {
      residual[0] = T(1e3);
      residual[1] = T(1e3);
      return true;
    }
    T xd, yd;
    calib::DistortNormalized(camera_.dist.data(), T(p.x() / p.z()), T(p.y() / p.z()), &xd, &yd);
    residual[0] = T(camera_.fx) * xd + T(camera_.cx) - T(pixel_.x());
    residual[1] = T(camera_.fy) * yd + T(camera_.cy) - T(pixel_.y());
    return true;
  }

  const calib::Camera& camera_;
  Eigen::Vector2d pixel_;
  Eigen::Vector3d point_;
};

ceres::LossFunction* MakeLoss(const RefineOptions& options) {
  switch (options.loss) {
    case RobustLoss::kNone: return nullptr;
    case RobustLoss::kHuber: return new ceres::HuberLoss(options.loss_scale_px);
    case RobustLoss::kCauchy: return new ceres::CauchyLoss(options.loss_scale_px);
  }
  return nullptr;
}

}  // namespace

double ReprojectionError(const calib::Camera& camera, const calib::Pose& pose,
                         const Eigen::Vector2d& pixel, const Eigen::Vector3d& point) {
  const Eigen::Vector3d p = pose.ToCamera(point);
  if (p.z() <= 1e-9) return std::numeric_limits<double>::infinity();
  return (camera.Project(p) - pixel).norm();
}

RefineResult RefinePose(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                        const std::vector<Eigen::Vector3d>& points, const calib::Pose& initial,
                        const RefineOptions& options) {
  RefineResult result;
  result.pose = initial;
  if (pixels.empty() || pixels.size() != points.size()) return result;

  Eigen::Quaterniond q = initial.q_cw.normalized();
  Eigen::Vector3d t = initial.t_cw;
  ceres::Problem::Options problem_options;
  // One loss object shared by every residual block; the problem owns it.
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::LossFunction* loss = MakeLoss(options);
  for (size_t i = 0; i < pixels.size(); ++i) {
    auto* cost = new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 4, 3>(
        new ReprojectionCost(camera, pixels[i], points[i]));
    problem.AddResidualBlock(cost, loss, q.coeffs().data(), t.data());
  }
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  result.stats.iterations = static_cast<int>(summary.iterations.size());
  result.stats.initial_cost = summary.initial_cost;
  result.stats.final_cost = summary.final_cost;
  result.stats.converged = summary.termination_type == ceres::CONVERGENCE;
  if (summary.termination_type == ceres::FAILURE || !q.coeffs().allFinite() || !t.allFinite())
    return result;
  result.pose = calib::Pose{q.normalized(), t};
  result.ok = true;
  return result;
}

}  // namespace arview::tracker
