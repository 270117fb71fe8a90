#pragma once
// The camera model shared by every module: pinhole + OpenCV radial-tangential distortion
// (k1, k2, p1, p2, k3), in OpenCV's pixel convention (centre of the top-left pixel at 0,0).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "base/error.h"
#include "calib/pose.h"

#include <array>
#include <cstdint>
#include <optional>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace arview::calib {

// A camera file or camera value that cannot be used; the message names the file and field.
struct CameraError : Error {
  using Error::Error;
};

// Applies OpenCV's radial-tangential distortion to normalised image coordinates (x, y).
// Templated so that Ceres cost functions project through exactly the same model.
// dist = {k1, k2, p1, p2, k3}.
template <typename T, typename D>
inline void DistortNormalized(const D* dist, const T& x, const T& y, T* xd, T* yd) {
  const T r2 = x * x + y * y;
  const T radial = T(1) + r2 * (T(dist[0]) + r2 * (T(dist[1]) + r2 * T(dist[4])));
  const T xy2 = T(2) * x * y;
  *xd = x * radial + T(dist[2]) * xy2 + T(dist[3]) * (r2 + T(2) * x * x);
  *yd = y * radial + T(dist[2]) * (r2 + T(2) * y * y) + T(dist[3]) * xy2;
}

// The 2x2 Jacobian of DistortNormalized with respect to (x, y), analytic.
Eigen::Matrix2d DistortionJacobian(const std::array<double, 5>& dist, double x, double y);

struct Camera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> dist{0, 0, 0, 0, 0};  // k1, k2, p1, p2, k3 (OpenCV order)
  // The lens focus the calibration holds for: a V4L2 camera's focus position
  // (V4L2_CID_FOCUS_ABSOLUTE, in the camera's units; camera.yaml's focus_absolute). A camera that
  // focuses elsewhere has another focal length. Unset: not known.
  std::optional<std::int64_t> focus;
  // False when the intrinsics were not measured but estimated (a focal length from the file's
  // metadata, a stated field of view, or a guess: `arview import` without --camera); `arview
  // map` then refines them in COLMAP's adjustment. camera.yaml's `calibrated: 0`.
  bool calibrated = true;
  // Where estimated intrinsics came from, in words (camera.yaml's `intrinsics_source`), e.g.
  // "a guess: focal length 0.6 x the diagonal"; empty for a calibration.
  std::string intrinsics_source;

  static Camera Pinhole(int width, int height, double fx, double fy, double cx, double cy);

  bool HasDistortion() const;
  cv::Matx33d K() const;
  Eigen::Matrix3d KEigen() const;
  cv::Mat DistCoeffs() const;  // 1x5 CV_64F, OpenCV order
  cv::Size Size() const { return {width, height}; }
  Camera WithoutDistortion() const;

  // A point in camera coordinates (z > 0 in front) to a distorted pixel.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_camera) const;
  // Normalised undistorted coordinates to a distorted pixel.
  Eigen::Vector2d NormalizedToPixel(const Eigen::Vector2d& normalized) const;
  // A distorted pixel to normalised undistorted coordinates (inverts the distortion by
  // Gauss-Newton to 1e-12, far tighter than cv::undistortPoints' fixed 5 iterations).
  Eigen::Vector2d PixelToNormalized(const Eigen::Vector2d& pixel) const;
  // A distorted pixel to the unit bearing vector OpenGV takes.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // A distorted pixel to where an ideal pinhole camera with the same K would see it.
  Eigen::Vector2d UndistortPixel(const Eigen::Vector2d& pixel) const;
  bool InImage(const Eigen::Vector2d& pixel, double border = 0) const;

  // Throws CameraError naming `source` and the offending field.
  void Validate(const std::string& source) const;
};

// An uncalibrated camera of the given size: principal point at the image's centre, no
// distortion, fx = fy = focal_px; `source` says where the focal length came from.
Camera EstimatedCamera(int width, int height, double focal_px, const std::string& source);

// The focal length in pixels of a camera whose horizontal field of view is `fov_deg` degrees
// (0 < fov < 180, else CameraError naming `what`).
double FocalFromHorizontalFov(int width, double fov_deg, const std::string& what);

// The focal length of a camera nothing is known of: 0.6 x the image's diagonal, a diagonal field
// of view of 80°, what phones' main cameras (24-28 mm equivalent) and webcams have. (COLMAP's
// own guess, 1.2 x the longer side, is a 45° lens: 67% long for phone-fox, whose maps then folded.)
double GuessedFocal(int width, int height);

// OpenCV FileStorage YAML with the names of OpenCV's calibration sample.
Camera LoadCamera(const std::filesystem::path& path);
void SaveCamera(const Camera& camera, const std::filesystem::path& path);

// The pose OpenCV's solvePnP family gives: a Rodrigues rotation vector and a translation, world
// to camera (3x1 CV_64F each).
Pose PoseFromOpenCv(const cv::Mat& rvec, const cv::Mat& tvec);

}  // namespace arview::calib
