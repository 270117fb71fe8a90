#pragma once
// Maps from recordings whose camera is not calibrated (`arview import` without --camera): COLMAP
// refines the focal length, the principal point and two radial terms in its bundle adjustment
// (its RADIAL model, from the image's centre and the estimated focal length), the map keeps the
// refined camera, and a camera whose refined values no lens has is flagged by the map's
// self-check (docs/mapping.md, "Maps without a calibration").

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "mapping/colmap_model.h"

namespace arview::mapping {

// The focal length that makes the pairs' fundamental matrices most nearly essential
// (Mendonça and Cipolla's self-calibration: E = Kᵀ F K has two equal singular values when K is
// right), for one camera with square pixels and the principal point (cx, cy) in COLMAP's pixels.
// Searched over 0.25 .. 5 x the longer side; nothing with fewer than kMinSelfCalibrationPairs
// pairs or when the best focal length lies on the search's edge. The estimate is trusted only
// when the pairs agree (median defect at most kTrustedEssentialDefect): a planar scene or an orbit
// with the optical axes in one plane leaves F unable to fix the focal length (phone-fox's
// wallpaper: a median defect of 0.199 at the best focal length, 0.295 at the true one).
struct FocalEstimate {
  double focal_px = 0;
  int pairs = 0;             // the pairs it was estimated from
  double median_cost = 0;    // (σ1 − σ2) / σ1 of their E at the estimate, the median
};
inline constexpr int kMinSelfCalibrationPairs = 5;
inline constexpr double kTrustedEssentialDefect = 0.05;
std::optional<FocalEstimate> FocalFromFundamentalMatrices(const std::vector<FundamentalPair>& pairs, int width,
                                                          int height, double cx, double cy);

// Before COLMAP's mapper: the focal length from the matched pairs (above) replaces the
// recording's estimate in the database's camera, so that the mapper starts near the truth (from
// a guess 60% off, phone-fox's models folded). Returns the camera the mapper starts from (the
// recording's own where too few pairs qualify); `note` gets one line saying which.
calib::Camera StartSelfCalibration(const std::filesystem::path& database, const calib::Camera& estimated,
                                   std::string* note);

// COLMAP's RADIAL camera (f, cx, cy, k1, k2) that starts the refinement of an uncalibrated camera.
std::vector<double> ColmapRadialParams(const calib::Camera& estimated);

// What no real lens gives: a focal length beyond 0.25 .. 5 x the longer side (a field of view
// over 127° or under 11°), a principal point outside the image's middle half, or a radial
// distortion that folds back (the distorted radius stops growing) inside the image's corners.
// One line each; none for a plausible camera.
std::vector<std::string> ImplausibleIntrinsics(const calib::Camera& camera);

// "the camera refined from <estimated source>: focal length 2304 -> 1379 px, k1 0.057, k2 -0.081"
std::string RefinedCameraNote(const calib::Camera& estimated, const calib::Camera& refined);

// <map_dir>/camera.yaml: the refined camera (still `calibrated: 0`, its source saying how it was
// refined), to give `run`, `track` or `record` the intrinsics the map found.
void WriteRefinedCamera(const calib::Camera& estimated, const calib::Camera& refined,
                        const std::filesystem::path& map_dir);

}  // namespace arview::mapping
