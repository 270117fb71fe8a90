#pragma once
// The pose refinement as Ceres solves it (autodiff, quaternion manifold): the reference that
// tests RefinePose's minimum and that bench_tracker times beside it. Not used by the tracker.

#include <ceres/ceres.h>

#include <Eigen/Geometry>

#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"
#include "tracker/refine_pose.h"

namespace arview::tracker::testing {

struct CeresReprojectionCost {
  CeresReprojectionCost(const calib::Camera& camera, const Eigen::Vector2d& pixel, const Eigen::Vector3d& point)
      : camera(camera), pixel(pixel), point(point) {}

  template <typename T>
  bool operator()(const T* q_xyzw, const T* t, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_xyzw);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t);
    const Eigen::Matrix<T, 3, 1> p = q * point.cast<T>() + translation;
    if (p.z() <= T(1e-9)) {  // as RefinePose: a constant residual behind the camera
      residual[0] = T(1e3);
      residual[1] = T(1e3);
      return true;
    }
    T xd, yd;
    calib::DistortNormalized(camera.dist.data(), T(p.x() / p.z()), T(p.y() / p.z()), &xd, &yd);
    residual[0] = T(camera.fx) * xd + T(camera.cx) - T(pixel.x());
    residual[1] = T(camera.fy) * yd + T(camera.cy) - T(pixel.y());
    return true;
  }

  const calib::Camera& camera;
  Eigen::Vector2d pixel;
  Eigen::Vector3d point;
};

// Returns the refined pose; `final_cost` receives Ceres' cost (1/2 sum rho).
inline calib::Pose RefinePoseWithCeres(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                                       const std::vector<Eigen::Vector3d>& points, const calib::Pose& initial,
                                       const RefineOptions& options, double* final_cost = nullptr) {
  Eigen::Quaterniond q = initial.q_cw.normalized();
  Eigen::Vector3d t = initial.t_cw;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::LossFunction* loss = nullptr;
  if (options.loss == RobustLoss::kHuber) loss = new ceres::HuberLoss(options.loss_scale_px);
  if (options.loss == RobustLoss::kCauchy) loss = new ceres::CauchyLoss(options.loss_scale_px);
  for (size_t i = 0; i < pixels.size(); ++i)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CeresReprojectionCost, 2, 4, 3>(
                                 new CeresReprojectionCost(camera, pixels[i], points[i])),
                             loss, q.coeffs().data(), t.data());
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (final_cost) *final_cost = summary.final_cost;
  return calib::Pose{q.normalized(), t};
}

}  // namespace arview::tracker::testing
