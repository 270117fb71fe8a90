#include "calib/camera.h"

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>

#include "base/input_guard.h"
#include "base/library_errors.h"
#include "base/opencv_matrix.h"

#include "base/atomic_file.h"

namespace arview::calib {

Camera Camera::Pinhole(int width, int height, double fx, double fy, double cx, double cy) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  return c;
}

bool Camera::HasDistortion() const {
  for (double d : dist) {
    if (d != 0.0) return true;
  }
  return false;
}

cv::Matx33d Camera::K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }

Eigen::Matrix3d Camera::KEigen() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Pose PoseFromOpenCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(R, rotation);
  cv::cv2eigen(tvec, translation);
  return Pose::FromRt(rotation, translation);
}

cv::Mat Camera::DistCoeffs() const {
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(0, i) = dist[i];
  return d;
}

Camera Camera::WithoutDistortion() const {
  Camera c = *this;
  c.dist = {0, 0, 0, 0, 0};
  return c;
}

Eigen::Vector2d Camera::NormalizedToPixel(const Eigen::Vector2d& n) const {
  double xd = 0, yd = 0;
  DistortNormalized(dist.data(), n.x(), n.y(), &xd, &yd);
  return {fx * xd + cx, fy * yd + cy};
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& p) const {
  return NormalizedToPixel({p.x() / p.z(), p.y() / p.z()});
}

Eigen::Matrix2d DistortionJacobian(const std::array<double, 5>& dist, double x, double y) {
  const double r2 = x * x + y * y;
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * r2 * k3);
  Eigen::Matrix2d J;
  J(0, 0) = radial + 2 * x * x * dradial_dr2 + 2 * p1 * y + 6 * p2 * x;
  J(0, 1) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
  J(1, 0) = J(0, 1);
  J(1, 1) = radial + 2 * y * y * dradial_dr2 + 6 * p1 * y + 2 * p2 * x;
  return J;
}

Eigen::Vector2d Camera::PixelToNormalized(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d target((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  if (!HasDistortion()) return target;
  Eigen::Vector2d n = target;
  for (int iter = 0; iter < 30; ++iter) {
    // Residual and analytic Jacobian of the distortion at n.
    Eigen::Vector2d d;
    DistortNormalized(dist.data(), n.x(), n.y(), &d.x(), &d.y());
    const Eigen::Vector2d residual = d - target;
    if (residual.squaredNorm() < 1e-26) break;
    const Eigen::Vector2d step = DistortionJacobian(dist, n.x(), n.y()).partialPivLu().solve(residual);
    if (!step.allFinite()) break;
    n -= step;
  }
  return n;
}

Eigen::Vector3d Camera::Unproject(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d n = PixelToNormalized(pixel);
  return Eigen::Vector3d(n.x(), n.y(), 1.0).normalized();
}

Eigen::Vector2d Camera::UndistortPixel(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d n = PixelToNormalized(pixel);
  return {fx * n.x() + cx, fy * n.y() + cy};
}

bool Camera::InImage(const Eigen::Vector2d& p, double border) const {
  return p.x() >= -0.5 + border && p.y() >= -0.5 + border && p.x() < width - 0.5 - border &&
         p.y() < height - 0.5 - border;
}

void Camera::Validate(const std::string& source) const {
  auto fail = [&](const std::string& field, const std::string& problem) {
    throw CameraError(source + ": " + field + " " + problem);
  };
  if (width <= 0) fail("image_width", "must be positive (is " + std::to_string(width) + ")");
  if (height <= 0) fail("image_height", "must be positive (is " + std::to_string(height) + ")");
  // Bounds far beyond any real camera, so that no later pixel arithmetic overflows.
  if (width > 65536) fail("image_width", "is larger than 65536 (is " + std::to_string(width) + ")");
  if (height > 65536) fail("image_height", "is larger than 65536 (is " + std::to_string(height) + ")");
  if (focus && (*focus < INT32_MIN || *focus > INT32_MAX))
    fail("focus_absolute", "must be a 32-bit V4L2 control value (is " + std::to_string(*focus) + ")");
  auto value = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  if (!(std::isfinite(fx) && fx > 0 && fx <= 1e7))
    fail("camera_matrix", "fx must be a positive number up to 1e7 (is " + value(fx) + ")");
  if (!(std::isfinite(fy) && fy > 0 && fy <= 1e7))
    fail("camera_matrix", "fy must be a positive number up to 1e7 (is " + value(fy) + ")");
  if (!(std::isfinite(cx) && cx >= 0 && cx <= width)) {
    fail("camera_matrix", "principal point cx=" + std::to_string(cx) + " lies outside the image width " +
                              std::to_string(width));
  }
  if (!(std::isfinite(cy) && cy >= 0 && cy <= height)) {
    fail("camera_matrix", "principal point cy=" + std::to_string(cy) +
                              " lies outside the image height " + std::to_string(height));
  }
  for (double d : dist) {
    if (!std::isfinite(d) || std::abs(d) > 1e6) {
      fail("distortion_coefficients", "holds " + value(d) + ", not a finite number of at most 1e6 in magnitude");
    }
  }
}

namespace {

cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& source, const char* name) {
  const cv::FileNode node = fs[name];
  if (node.empty()) throw CameraError(source + ": field " + name + " is missing");
  cv::Mat m;
  try {
    ReadOpenCvMatrix(node, m, source + ": field " + name);
  } catch (const InputError& e) {
    throw CameraError(e.what());
  }
  if (m.empty()) throw CameraError(source + ": field " + name + " is empty or not a matrix");
  m.convertTo(m, CV_64F);
  return m;
}

int ReadInt(const cv::FileStorage& fs, const std::string& source, const char* name) {
  const cv::FileNode node = fs[name];
  if (node.empty()) throw CameraError(source + ": field " + name + " is missing");
  if (!node.isInt()) throw CameraError(source + ": field " + name + " must be an integer");
  return static_cast<int>(node);
}

}  // namespace

namespace {

// The keys OpenCV's calibration samples write besides the camera itself: they describe the
// calibration run, not the camera, so they are accepted and not used.
const std::set<std::string>& InformationalKeys() {
  static const std::set<std::string> keys{
      "calibration_time", "nframes", "nr_of_frames", "board_width", "board_height", "square_size",
      "aspectRatio", "fix_aspect_ratio", "flags", "fisheye_model", "avg_reprojection_error",
      "per_view_reprojection_errors", "extrinsic_parameters", "image_points", "grid_points"};
  return keys;
}

// A plain decimal integer that fits 32 bits, as V4L2 control values do.
bool IsInt32Text(const std::string& text) {
  const std::string number = text.substr(0, text.find_last_not_of(" \t", text.find(" #")) + 1);  // a comment after it
  std::int64_t value = 0;
  const char* end = number.data() + number.size();
  const auto [stop, error] = std::from_chars(number.data(), end, value);
  return !number.empty() && error == std::errc() && stop == end && value >= INT32_MIN && value <= INT32_MAX;
}

// What is checked on the text before OpenCV's FileStorage parses it, because FileStorage
// itself crashes on it: a matrix header whose rows/cols are not small plain numbers makes it
// allocate tens of GB, deep nesting overflows its recursive parser's stack, and a key given
// twice silently keeps the first value.
void PrecheckCameraText(const std::string& text, const std::string& source) {
  std::istringstream lines(text);
  std::string line;
  std::string field;  // the top-level key the line belongs to
  for (int number = 1; std::getline(lines, line); ++number) {
    const size_t key_start = line.find_first_not_of(' ');
    if (key_start == std::string::npos) continue;
    const size_t colon = line.find(':', key_start);
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(key_start, colon - key_start);
    if (key_start == 0) field = key;
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(" \t"));
    value.erase(value.find_last_not_of(" \t\r") + 1);
    auto fail = [&](const std::string& problem) {
      throw CameraError(source + ": line " + std::to_string(number) + ": " + problem);
    };
    // OpenCV's reader takes an empty key and fails later with a bare "basic_string::_M_create".
    if (key.empty()) {
      fail(key_start == 0 ? std::string("a key is empty (before ':')")
                          : "a key of " + field + " is empty (before ': " + value + "'; a matrix holds rows, cols, dt, data)");
    }
    // OpenCV's reader wraps integers beyond 32 bits (2147483648 read as -2147483648).
    if (key_start == 0 && key == "focus_absolute" && !IsInt32Text(value)) {
      fail("focus_absolute '" + value + "' must be a whole number from " + std::to_string(INT32_MIN) + " to " +
           std::to_string(INT32_MAX) + " (a 32-bit V4L2 control value)");
    }
    if (key == "rows" || key == "cols") {
      const bool small_number = !value.empty() && value.size() <= 2 &&
                                value.find_first_not_of("0123456789") == std::string::npos && std::stoi(value) > 0 &&
                                std::stoi(value) <= 16;
      if (!small_number) fail("matrix " + key + " '" + value + "' is not a number from 1 to 16");
    } else if (key == "dt" && value != "d" && value != "f") {
      fail("matrix type dt: " + value + " is not a floating-point type (d or f)");
    }
  }
  // After the camera's own line checks (their messages are the more specific), before the
  // duplicate-key scan.
  try {
    RequireOpenCvYamlShape(text, 8, source);
  } catch (const InputError& e) {
    throw CameraError(e.what());
  }
  if (const auto d = FindDuplicateYamlKey(text)) {
    throw CameraError(source + ": line " + std::to_string(d->line) + ": key '" + d->key + "' given twice (first on line " +
                      std::to_string(d->first_line) + ")");
  }
}

// Every top-level key is either used or known to be informational; anything else (a typo, a
// field of another camera model) is refused rather than ignored.
void RefuseUnknownKeys(const cv::FileStorage& fs, const std::string& source) {
  static const std::set<std::string> used{"image_width",    "image_height",     "camera_matrix",
                                          "distortion_coefficients", "focus_absolute", "calibrated",
                                          "intrinsics_source"};
  const cv::FileNode root = fs.root();
  for (const std::string& key : root.keys()) {
    if (used.count(key) == 0 && InformationalKeys().count(key) == 0) {
      throw CameraError(source + ": unknown key '" + key + "' (a camera file holds image_width, image_height, " +
                        "camera_matrix, distortion_coefficients, focus_absolute, calibrated, intrinsics_source)");
    }
  }
  const cv::FileNode fisheye = fs["fisheye_model"];
  if (!fisheye.empty() && (!fisheye.isInt() || static_cast<int>(fisheye) != 0)) {
    throw CameraError(source + ": fisheye_model is set: arview's camera model is the pinhole with radial-tangential "
                      "distortion, not the fisheye model");
  }
}

// K must be [fx 0 cx; 0 fy cy; 0 0 1]: a skew or a last row other than 0 0 1 is a camera
// model arview does not have, and is refused rather than dropped.
void RequirePinholeMatrix(const cv::Mat& K, const std::string& source) {
  auto fail = [&](const std::string& problem) { throw CameraError(source + ": camera_matrix " + problem); };
  if (K.at<double>(0, 1) != 0.0) fail("has a skew K[0][1] = " + std::to_string(K.at<double>(0, 1)) + ": not supported (must be 0)");
  if (K.at<double>(1, 0) != 0.0) fail("K[1][0] must be 0 (is " + std::to_string(K.at<double>(1, 0)) + ")");
  if (K.at<double>(2, 0) != 0.0 || K.at<double>(2, 1) != 0.0 || K.at<double>(2, 2) != 1.0) {
    fail("last row must be 0 0 1");
  }
}

}  // namespace

namespace {

Camera LoadCameraFile(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::string text;
  try {
    text = ReadFileUpTo(path, kMaxCameraFileBytes);
  } catch (const InputError& e) {
    throw CameraError(std::string(e.what()) + " (expected a camera file)");
  }
  PrecheckCameraText(text, source);
  cv::FileStorage fs;
  try {
    if (!fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML)) {
      throw CameraError(source + ": cannot be opened as an OpenCV FileStorage file");
    }
  } catch (const cv::Exception& e) {
    throw CameraError(source + ": is not valid OpenCV FileStorage YAML (" + e.err + ")");
  }
  Camera c;
  c.width = ReadInt(fs, source, "image_width");
  c.height = ReadInt(fs, source, "image_height");
  const cv::Mat K = ReadMatrix(fs, source, "camera_matrix");
  if (K.rows != 3 || K.cols != 3) throw CameraError(source + ": field camera_matrix must be 3x3");
  RequirePinholeMatrix(K, source);
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  if (!fs["distortion_coefficients"].empty()) {
    const cv::Mat d = ReadMatrix(fs, source, "distortion_coefficients");
    const int n = static_cast<int>(d.total());
    if (n != 4 && n != 5) {
      throw CameraError(source + ": field distortion_coefficients must hold 4 or 5 values (k1 k2 p1 p2 [k3]), has " +
                        std::to_string(n));
    }
    for (int i = 0; i < n; ++i) c.dist[i] = d.at<double>(i);
  }
  if (!fs["focus_absolute"].empty()) c.focus = ReadInt(fs, source, "focus_absolute");
  if (!fs["calibrated"].empty()) {
    const int calibrated = ReadInt(fs, source, "calibrated");
    if (calibrated != 0 && calibrated != 1) throw CameraError(source + ": calibrated must be 0 or 1 (is " + std::to_string(calibrated) + ")");
    c.calibrated = calibrated == 1;
  }
  if (!fs["intrinsics_source"].empty()) {
    const cv::FileNode node = fs["intrinsics_source"];
    if (!node.isString()) throw CameraError(source + ": intrinsics_source must be a text");
    c.intrinsics_source = static_cast<std::string>(node);
  }
  RefuseUnknownKeys(fs, source);
  c.Validate(source);
  return c;
}

}  // namespace

Camera EstimatedCamera(int width, int height, double focal_px, const std::string& source) {
  Camera c = Camera::Pinhole(width, height, focal_px, focal_px, width / 2.0 - 0.5, height / 2.0 - 0.5);
  c.calibrated = false;
  c.intrinsics_source = source;
  c.Validate("the estimated camera (" + source + ")");
  return c;
}

double FocalFromHorizontalFov(int width, double fov_deg, const std::string& what) {
  if (!(std::isfinite(fov_deg) && fov_deg > 0 && fov_deg < 180)) {
    std::ostringstream s;
    s << what << ": the horizontal field of view must be between 0 and 180 degrees (is " << fov_deg << ")";
    throw CameraError(s.str());
  }
  return width / 2.0 / std::tan(fov_deg * M_PI / 360.0);
}

double GuessedFocal(int width, int height) { return 0.6 * std::hypot(width, height); }

Camera LoadCamera(const std::filesystem::path& path) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<CameraError>(path.string(), [&] { return LoadCameraFile(path); });
}

void SaveCamera(const Camera& camera, const std::filesystem::path& path) {
  camera.Validate("camera to save as " + path.string());
  // Encoded in memory (FileStorage's YAML, as a file would be), then written atomically.
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << "image_width" << camera.width;
  fs << "image_height" << camera.height;
  fs << "camera_matrix" << cv::Mat(camera.K());
  fs << "distortion_coefficients" << camera.DistCoeffs();
  // FileStorage writes 32-bit integers: a V4L2 control's value is one.
  if (camera.focus) fs << "focus_absolute" << static_cast<int>(*camera.focus);
  if (!camera.calibrated) fs << "calibrated" << 0;
  if (!camera.intrinsics_source.empty()) fs << "intrinsics_source" << camera.intrinsics_source;
  WriteFileAtomically(path, fs.releaseAndGetString());
}

}  // namespace arview::calib
