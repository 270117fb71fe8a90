#include "mapping/self_calibration.h"

#include <algorithm>
#include <limits>

#include <Eigen/SVD>

#include "base/stats.h"
#include <cmath>

namespace arview::mapping {
namespace {

constexpr double kMinFocalRatio = 0.25;  // focal / longer side: a 127° field of view
constexpr double kMaxFocalRatio = 5.0;   // an 11° one

// The distorted radius r (1 + k1 r² + k2 r⁴ + k3 r⁶) must grow up to the corners' radius; where
// its derivative is not positive, two rays land on one pixel.
bool RadialFoldsInside(const calib::Camera& c, double corner_radius) {
  const double k1 = c.dist[0], k2 = c.dist[1], k3 = c.dist[4];
  constexpr int kSteps = 200;
  for (int i = 1; i <= kSteps; ++i) {
    const double r2 = std::pow(corner_radius * i / kSteps, 2);
    const double derivative = 1 + 3 * k1 * r2 + 5 * k2 * r2 * r2 + 7 * k3 * r2 * r2 * r2;
    if (derivative <= 0) return true;
  }
  return false;
}

Eigen::Matrix3d SquarePixelK(double focal, double cx, double cy) {
  Eigen::Matrix3d K;
  K << focal, 0, cx, 0, focal, cy, 0, 0, 1;
  return K;
}

// How far E = Kᵀ F K is from an essential matrix: (σ1 − σ2) / σ1, 0 for one; 1 for a zero matrix.
double EssentialDefect(const Eigen::Matrix3d& K, const Eigen::Matrix3d& F) {
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(K.transpose() * F * K).singularValues();
  return sv[0] > 0 ? (sv[0] - sv[1]) / sv[0] : 1.0;
}

// The pairs' robust cost at one focal length: the mean defect over the pairs, each capped at 0.5
// so that a few pairs with a wrong F cannot pull the minimum.
double EssentialCost(const std::vector<Eigen::Matrix3d>& fundamentals, double focal, double cx, double cy) {
  const Eigen::Matrix3d K = SquarePixelK(focal, cx, cy);
  double sum = 0;
  for (const Eigen::Matrix3d& F : fundamentals) sum += std::min(EssentialDefect(K, F), 0.5);
  return sum / static_cast<double>(fundamentals.size());
}

}  // namespace

std::optional<FocalEstimate> FocalFromFundamentalMatrices(const std::vector<FundamentalPair>& pairs, int width,
                                                          int height, double cx, double cy) {
  // The best-matched pairs: their F is the most exact. At most 100, as more adds time only.
  std::vector<FundamentalPair> sorted = pairs;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.inliers > b.inliers; });
  if (sorted.size() > 100) sorted.resize(100);
  if (static_cast<int>(sorted.size()) < kMinSelfCalibrationPairs) return std::nullopt;
  std::vector<Eigen::Matrix3d> fundamentals;
  for (const FundamentalPair& p : sorted) fundamentals.push_back(p.fundamental / p.fundamental.norm());

  // A grid in log(f), then golden-section search in the best cell's neighbourhood.
  const double longer = std::max(width, height);
  const double lo = std::log(kMinFocalRatio * longer), hi = std::log(kMaxFocalRatio * longer);
  constexpr int kSteps = 200;
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= kSteps; ++i) {
    const double cost = EssentialCost(fundamentals, std::exp(lo + (hi - lo) * i / kSteps), cx, cy);
    if (cost < best_cost) best_cost = cost, best = i;
  }
  if (best == 0 || best == kSteps) return std::nullopt;  // no minimum inside the range
  double a = lo + (hi - lo) * (best - 1) / kSteps, b = lo + (hi - lo) * (best + 1) / kSteps;
  const double golden = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < 60; ++i) {
    const double m1 = b - golden * (b - a), m2 = a + golden * (b - a);
    if (EssentialCost(fundamentals, std::exp(m1), cx, cy) < EssentialCost(fundamentals, std::exp(m2), cx, cy)) b = m2;
    else a = m1;
  }
  FocalEstimate estimate;
  estimate.focal_px = std::exp((a + b) / 2);
  estimate.pairs = static_cast<int>(fundamentals.size());
  const Eigen::Matrix3d K = SquarePixelK(estimate.focal_px, cx, cy);
  std::vector<double> defects;
  for (const Eigen::Matrix3d& F : fundamentals) defects.push_back(EssentialDefect(K, F));
  estimate.median_cost = Median(defects);
  return estimate;
}

calib::Camera StartSelfCalibration(const std::filesystem::path& database, const calib::Camera& estimated,
                                   std::string* note) {
  // COLMAP's pixel centres are at +0.5, as F's.
  const std::optional<FocalEstimate> focal = FocalFromFundamentalMatrices(
      ReadFundamentalMatrices(database), estimated.width, estimated.height, estimated.cx + 0.5, estimated.cy + 0.5);
  if (!focal) {
    if (note) *note = "too few frame pairs of a general motion to estimate the focal length from (" +
                      std::to_string(kMinSelfCalibrationPairs) + " needed): COLMAP starts from " +
                      estimated.intrinsics_source;
    return estimated;
  }
  if (focal->median_cost > kTrustedEssentialDefect) {
    if (note) *note = "the frames' epipolar geometry does not fix the focal length (median essential-matrix defect " +
                      Fixed(focal->median_cost, 3) + " at its best, " + Fixed(focal->focal_px, 0) +
                      " px; a planar scene or an orbit): COLMAP starts from " + estimated.intrinsics_source;
    return estimated;
  }
  calib::Camera start = estimated;
  start.fx = start.fy = focal->focal_px;
  start.intrinsics_source = "the frames' epipolar geometry (" + std::to_string(focal->pairs) + " pairs)";
  SetSingleCameraParams(database, ColmapRadialParams(start));
  if (note) {
    *note = "focal length from the frames' epipolar geometry: " + Fixed(focal->focal_px, 1) + " px (" +
            std::to_string(focal->pairs) + " pairs, median essential-matrix defect " + Fixed(focal->median_cost, 3) +
            "; the import said " + Fixed(estimated.fx, 0) + " px)";
  }
  return start;
}

std::vector<double> ColmapRadialParams(const calib::Camera& estimated) {
  // COLMAP's pixel centres are at +0.5 (docs/architecture.md, "Pixel coordinates").
  return {(estimated.fx + estimated.fy) / 2, estimated.cx + 0.5, estimated.cy + 0.5, estimated.dist[0],
          estimated.dist[1]};
}

std::vector<std::string> ImplausibleIntrinsics(const calib::Camera& c) {
  std::vector<std::string> problems;
  const double longer = std::max(c.width, c.height);
  const double focal = (c.fx + c.fy) / 2;
  if (focal < kMinFocalRatio * longer || focal > kMaxFocalRatio * longer) {
    const double fov_deg = 2 * std::atan(longer / 2 / focal) * 180 / M_PI;
    problems.push_back("the camera's focal length " + Fixed(focal, 0) + " px is a field of view of " + Fixed(fov_deg, 0) +
                       "° across the longer side, which no ordinary lens has: the intrinsics are likely wrong; "
                       "calibrate the camera (arview calibrate) and map with its camera.yaml");
  }
  if (std::abs(c.cx - (c.width - 1) / 2.0) > c.width / 4.0 || std::abs(c.cy - (c.height - 1) / 2.0) > c.height / 4.0) {
    problems.push_back("the camera's principal point (" + Fixed(c.cx, 0) + ", " + Fixed(c.cy, 0) +
                       ") lies outside the image's middle half: the intrinsics are likely wrong; calibrate the camera");
  }
  const double corner_radius = std::hypot(std::max(c.cx, c.width - 1 - c.cx) / c.fx, std::max(c.cy, c.height - 1 - c.cy) / c.fy);
  if (RadialFoldsInside(c, corner_radius)) {
    problems.push_back("the camera's radial distortion (k1 " + Fixed(c.dist[0], 3) + ", k2 " + Fixed(c.dist[1], 3) +
                       ") folds back inside the image (two directions on one pixel): the intrinsics are likely wrong; "
                       "calibrate the camera");
  }
  return problems;
}

std::string RefinedCameraNote(const calib::Camera& estimated, const calib::Camera& refined) {
  return "the camera was not calibrated (" + estimated.intrinsics_source + "); COLMAP refined it: focal length " +
         Fixed(estimated.fx, 0) + " -> " + Fixed(refined.fx, 1) + " px, principal point (" + Fixed(refined.cx, 1) + ", " +
         Fixed(refined.cy, 1) + "), k1 " + Fixed(refined.dist[0], 4) + ", k2 " + Fixed(refined.dist[1], 4) +
         " (written to the map and to its camera.yaml)";
}

void WriteRefinedCamera(const calib::Camera& estimated, const calib::Camera& refined,
                        const std::filesystem::path& map_dir) {
  calib::Camera written = refined;
  written.calibrated = false;
  written.intrinsics_source = "refined by arview map (COLMAP's bundle adjustment) from " + estimated.intrinsics_source;
  calib::SaveCamera(written, map_dir / "camera.yaml");
}

}  // namespace arview::mapping
