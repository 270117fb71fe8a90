#include "tracker/ransac_p3p.h"

#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>

#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace arview::tracker {
namespace {

using Problem = opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;

Problem::algorithm_t ToOpenGV(MinimalSolver solver) {
  switch (solver) {
    case MinimalSolver::kKneip: return Problem::KNEIP;
    case MinimalSolver::kGao: return Problem::GAO;
    case MinimalSolver::kEpnp: return Problem::EPNP;
  }
  return Problem::KNEIP;
}

// OpenGV seeds its generator either with the clock or with a constant; replays must be
// repeatable with a chosen seed, so the generator is rebuilt from our seed.
void Seed(Problem& problem, std::uint32_t seed) {
  problem.rng_alg_.seed(seed);
  problem.rng_gen_ = std::make_shared<std::function<int()>>(
      std::bind(*problem.rng_dist_, problem.rng_alg_));
}

}  // namespace

MinimalSolver ParseMinimalSolver(const std::string& name) { return ParseEnum<MinimalSolver>(name, "minimal solver"); }

double PixelThresholdToOpenGV(double pixels, double focal_px) {
  return 1.0 - std::cos(std::atan(pixels / focal_px));
}

int MinimalSampleSize(MinimalSolver solver) {
  // KNEIP and GAO draw a fourth point to pick among P3P's up to four solutions; EPnP needs six.
  return solver == MinimalSolver::kEpnp ? 6 : 4;
}

RansacResult RansacAbsolutePose(const std::vector<Eigen::Vector3d>& bearings,
                                const std::vector<Eigen::Vector3d>& points,
                                const RansacOptions& options) {
  if (bearings.size() != points.size())
    throw Error("RansacAbsolutePose: bearings and points differ in count");
  RansacResult result;
  if (static_cast<int>(bearings.size()) < MinimalSampleSize(options.solver)) return result;

  const opengv::bearingVectors_t gv_bearings(bearings.begin(), bearings.end());
  const opengv::points_t gv_points(points.begin(), points.end());
  opengv::absolute_pose::CentralAbsoluteAdapter adapter(gv_bearings, gv_points);
  auto problem = std::make_shared<Problem>(adapter, ToOpenGV(options.solver), /*randomSeed=*/false);
  Seed(*problem, options.seed);

  opengv::sac::Ransac<Problem> ransac;
  ransac.sac_model_ = problem;
  ransac.threshold_ = options.threshold;
  ransac.max_iterations_ = options.max_iterations;
  ransac.probability_ = options.success_probability;
  const bool ok = ransac.computeModel(0);
  result.stats.iterations = ransac.iterations_;
  if (!ok || ransac.inliers_.empty()) return result;

  const opengv::transformation_t& T = ransac.model_coefficients_;  // [R_wc | C]
  const Eigen::Matrix3d R_wc = T.leftCols<3>();
  if (!R_wc.allFinite() || !T.col(3).allFinite()) return result;
  result.pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond(R_wc), T.col(3));
  result.inliers = ransac.inliers_;
  result.stats.inliers = static_cast<int>(result.inliers.size());
  result.found = true;
  return result;
}

}  // namespace arview::tracker
