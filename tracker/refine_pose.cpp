#include "tracker/refine_pose.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace arview::tracker {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// A point behind the camera has no meaningful projection: it gets a large constant residual
// (and no gradient), so that the robust loss does not pull the pose through the image plane.
constexpr double kBehindResidualPx = 1e3;

// The robust loss rho(s) of a squared residual s, as Ceres defines it (cost = 1/2 sum rho).
double Rho(const RefineOptions& options, double s) {
  const double a = options.loss_scale_px;
  switch (options.loss) {
    case RobustLoss::kNone: return s;
    case RobustLoss::kHuber: return s <= a * a ? s : 2 * a * std::sqrt(s) - a * a;
    case RobustLoss::kCauchy: return a * a * std::log1p(s / (a * a));
  }
  return s;
}

// rho'(s): the weight of a residual in iteratively reweighted least squares. Its normal
// equations have the robust cost's own stationary points.
double RhoDerivative(const RefineOptions& options, double s) {
  const double a = options.loss_scale_px;
  switch (options.loss) {
    case RobustLoss::kNone: return 1;
    case RobustLoss::kHuber: return s <= a * a ? 1 : a / std::sqrt(s);
    case RobustLoss::kCauchy: return 1 / (1 + s / (a * a));
  }
  return 1;
}

// Residual (projected − observed, pixels) of one correspondence and, when `jacobian` is given,
// its derivative with respect to (ω, δt) in p_c = Exp(ω)·R·X + t + δt. False when behind.
bool Residual(const calib::Camera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
              const Eigen::Vector2d& pixel, const Eigen::Vector3d& point, Eigen::Vector2d* residual,
              Eigen::Matrix<double, 2, 6>* jacobian) {
  const Eigen::Vector3d rotated = R * point;
  const Eigen::Vector3d p = rotated + t;
  if (p.z() <= 1e-9) {
    *residual = Eigen::Vector2d::Constant(kBehindResidualPx);
    if (jacobian) jacobian->setZero();
    return false;
  }
  const double inv_z = 1 / p.z();
  const double x = p.x() * inv_z, y = p.y() * inv_z;
  *residual = camera.NormalizedToPixel({x, y}) - pixel;
  if (!jacobian) return true;
  // d pixel / d normalised = diag(f) · distortion Jacobian; d normalised / d p_c.
  Eigen::Matrix2d d_pixel = calib::DistortionJacobian(camera.dist, x, y);
  d_pixel.row(0) *= camera.fx;
  d_pixel.row(1) *= camera.fy;
  Eigen::Matrix<double, 2, 3> d_normalized;
  d_normalized << inv_z, 0, -x * inv_z, 0, inv_z, -y * inv_z;
  const Eigen::Matrix<double, 2, 3> d_p = d_pixel * d_normalized;
  // d p_c / d ω = −[R·X]×, d p_c / d δt = I.
  Eigen::Matrix3d minus_skew;
  minus_skew << 0, rotated.z(), -rotated.y(), -rotated.z(), 0, rotated.x(), rotated.y(), -rotated.x(), 0;
  jacobian->leftCols<3>() = d_p * minus_skew;
  jacobian->rightCols<3>() = d_p;
  return true;
}

double Cost(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
            const std::vector<Eigen::Vector3d>& points, const Eigen::Quaterniond& q, const Eigen::Vector3d& t,
            const RefineOptions& options) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  double cost = 0;
  Eigen::Vector2d r;
  for (size_t i = 0; i < pixels.size(); ++i) {
    Residual(camera, R, t, pixels[i], points[i], &r, nullptr);
    cost += Rho(options, r.squaredNorm());
  }
  return 0.5 * cost;
}

// The weighted normal equations H·δ = −g at (q, t).
void NormalEquations(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                     const std::vector<Eigen::Vector3d>& points, const Eigen::Quaterniond& q,
                     const Eigen::Vector3d& t, const RefineOptions& options, Matrix6d* H, Vector6d* g) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  H->setZero();
  g->setZero();
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (!Residual(camera, R, t, pixels[i], points[i], &r, &J)) continue;
    const double w = RhoDerivative(options, r.squaredNorm());
    const Eigen::Matrix<double, 6, 2> weighted = w * J.transpose();
    H->noalias() += weighted * J;
    g->noalias() += weighted * r;
  }
}

Eigen::Quaterniond RotateBy(const Eigen::Vector3d& omega, const Eigen::Quaterniond& q) {
  const double angle = omega.norm();
  if (angle < 1e-300) return q;
  return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle)) * q).normalized();
}

}  // namespace

double ReprojectionError(const calib::Camera& camera, const calib::Pose& pose,
                         const Eigen::Vector2d& pixel, const Eigen::Vector3d& point) {
  const Eigen::Vector3d p = pose.ToCamera(point);
  if (p.z() <= 1e-9) return std::numeric_limits<double>::infinity();
  return (camera.Project(p) - pixel).norm();
}

// Levenberg-Marquardt on the 6 degrees of freedom with analytic Jacobians, as PoseLib refines
// poses. Ceres (autodiff, quaternion manifold) did the same job but spent most of a solve on
// building and evaluating the problem: BM_RefinePose took 1023 µs for 250 correspondences with
// Ceres, 147 µs with this, which reaches the same minimum (test RefinePose.ReachesCeresMinimum).
RefineResult RefinePose(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                        const std::vector<Eigen::Vector3d>& points, const calib::Pose& initial,
                        const RefineOptions& options) {
  RefineResult result;
  result.pose = initial;
  if (pixels.empty() || pixels.size() != points.size()) return result;

  Eigen::Quaterniond q = initial.q_cw.normalized();
  Eigen::Vector3d t = initial.t_cw;
  double cost = Cost(camera, pixels, points, q, t, options);
  result.stats.initial_cost = cost;
  if (!std::isfinite(cost) || !q.coeffs().allFinite() || !t.allFinite()) return result;

  double lambda = 1e-4;  // damping, relative to the normal matrix's diagonal
  Matrix6d H;
  Vector6d g;
  bool linearized = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    result.stats.iterations = iteration + 1;
    if (!linearized) {
      NormalEquations(camera, pixels, points, q, t, options, &H, &g);
      linearized = true;
      if (g.lpNorm<Eigen::Infinity>() < 1e-12) {
        result.stats.converged = true;
        break;
      }
    }
    Matrix6d damped = H;
    damped.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
    const Vector6d step = -damped.ldlt().solve(g);
    if (!step.allFinite()) break;
    const Eigen::Quaterniond q_new = RotateBy(step.head<3>(), q);
    const Eigen::Vector3d t_new = t + step.tail<3>();
    const double new_cost = Cost(camera, pixels, points, q_new, t_new, options);
    if (std::isfinite(new_cost) && new_cost < cost) {
      const double decrease = (cost - new_cost) / cost;
      q = q_new;
      t = t_new;
      cost = new_cost;
      linearized = false;
      lambda = std::max(lambda / 10, 1e-12);
      // Ceres' function tolerance, and a step too small to move the pose (parameter tolerance).
      if (decrease < options.function_tolerance ||
          step.norm() < 1e-10 * (t.norm() + 1)) {
        result.stats.converged = true;
        break;
      }
    } else {
      lambda *= 10;
      if (lambda > 1e12) {  // no step downhill left: at the minimum to machine precision
        result.stats.converged = true;
        break;
      }
    }
  }
  result.stats.final_cost = cost;
  if (!q.coeffs().allFinite() || !t.allFinite()) return result;
  result.pose = calib::Pose{q.normalized(), t};
  result.ok = true;
  return result;
}

}  // namespace arview::tracker
