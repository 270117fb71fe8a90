#pragma once
// Minimal-solver RANSAC on bearing vectors with OpenGV's AbsolutePoseSacProblem.
// One solver, one entry point: options in, pose + inliers + stats out.

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "base/enum_table.h"
#include "calib/pose.h"

namespace arview::tracker {

enum class MinimalSolver { kKneip, kGao, kEpnp };

constexpr auto EnumNames(MinimalSolver) {
  return EnumTable<MinimalSolver, 3>{
      {{MinimalSolver::kKneip, "kneip"}, {MinimalSolver::kGao, "gao"}, {MinimalSolver::kEpnp, "epnp"}}};
}
// Parses "kneip" | "gao" | "epnp"; throws arview::Error naming the value otherwise.
// (Back: arview::ToString.)
MinimalSolver ParseMinimalSolver(const std::string& name);

struct RansacOptions {
  MinimalSolver solver = MinimalSolver::kKneip;
  // Inlier threshold as an angle between the observed bearing and the reprojected one,
  // expressed in OpenGV's units (1 − cos angle). Use PixelThresholdToOpenGV() to get it.
  double threshold = 0;
  int max_iterations = 1000;
  double success_probability = 0.999;
  std::uint32_t seed = 0;
};

struct RansacStats {
  int iterations = 0;
  int inliers = 0;
};

struct RansacResult {
  bool found = false;
  calib::Pose pose;          // world → camera (converted from OpenGV's camera → world)
  std::vector<int> inliers;  // indices into the input
  RansacStats stats;
};

// 1 − cos(atan(pixels / focal)): the angle a `pixels`-long error subtends at the image centre.
double PixelThresholdToOpenGV(double pixels, double focal_px);

// Number of correspondences the minimal solver draws per hypothesis.
int MinimalSampleSize(MinimalSolver solver);

// bearings: unit vectors in the camera frame; points: world points, same order.
// Fewer correspondences than the sample size returns found = false without calling OpenGV.
RansacResult RansacAbsolutePose(const std::vector<Eigen::Vector3d>& bearings,
                                const std::vector<Eigen::Vector3d>& points,
                                const RansacOptions& options);

}  // namespace arview::tracker
