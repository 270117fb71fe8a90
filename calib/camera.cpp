#include "calib/camera.h"

#include <Eigen/Dense>

#include <cmath>
#include <fstream>

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

Eigen::Vector2d Camera::PixelToNormalized(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d target((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  if (!HasDistortion()) return target;
  Eigen::Vector2d n = target;
  for (int iter = 0; iter < 30; ++iter) {
    // Residual and analytic Jacobian of the distortion at n.
    const double x = n.x(), y = n.y();
    const double r2 = x * x + y * y;
    const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * r2 * k3);
    Eigen::Vector2d d;
    DistortNormalized(dist.data(), x, y, &d.x(), &d.y());
    const Eigen::Vector2d residual = d - target;
    if (residual.squaredNorm() < 1e-26) break;
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2 * x * x * dradial_dr2 + 2 * p1 * y + 6 * p2 * x;
    J(0, 1) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
    J(1, 0) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
    J(1, 1) = radial + 2 * y * y * dradial_dr2 + 6 * p1 * y + 2 * p2 * x;
    const Eigen::Vector2d step = J.partialPivLu().solve(residual);
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
  if (!(std::isfinite(fx) && fx > 0)) fail("camera_matrix", "fx must be a positive number");
  if (!(std::isfinite(fy) && fy > 0)) fail("camera_matrix", "fy must be a positive number");
  if (!(std::isfinite(cx) && cx >= 0 && cx <= width)) {
    fail("camera_matrix", "principal point cx=" + std::to_string(cx) + " lies outside the image width " +
                              std::to_string(width));
  }
  if (!(std::isfinite(cy) && cy >= 0 && cy <= height)) {
    fail("camera_matrix", "principal point cy=" + std::to_string(cy) +
                              " lies outside the image height " + std::to_string(height));
  }
  for (double d : dist) {
    if (!std::isfinite(d)) fail("distortion_coefficients", "holds a value that is not a finite number");
  }
}

namespace {

cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& source, const char* name) {
  const cv::FileNode node = fs[name];
  if (node.empty()) throw CameraError(source + ": field " + name + " is missing");
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    throw CameraError(source + ": field " + name + " is not an OpenCV matrix");
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

Camera LoadCamera(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw CameraError(source + ": camera file does not exist or is not a file");
  }
  cv::FileStorage fs;
  try {
    if (!fs.open(source, cv::FileStorage::READ)) {
      throw CameraError(source + ": cannot be opened as an OpenCV FileStorage file");
    }
  } catch (const cv::Exception& e) {
    throw CameraError(source + ": is not valid OpenCV FileStorage YAML/XML (" + e.err + ")");
  }
  Camera c;
  c.width = ReadInt(fs, source, "image_width");
  c.height = ReadInt(fs, source, "image_height");
  const cv::Mat K = ReadMatrix(fs, source, "camera_matrix");
  if (K.rows != 3 || K.cols != 3) throw CameraError(source + ": field camera_matrix must be 3x3");
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
  c.Validate(source);
  return c;
}

void SaveCamera(const Camera& camera, const std::filesystem::path& path) {
  camera.Validate("camera to save as " + path.string());
  // Write to a sibling file and rename, so that a failure never leaves a half-written camera.
  const std::filesystem::path tmp = path.string() + ".tmp.yaml";
  {
    std::ofstream probe(tmp);
    if (!probe) throw CameraError(path.string() + ": cannot write here (directory missing or not writable)");
  }
  cv::FileStorage fs(tmp.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw CameraError(path.string() + ": cannot write here");
  fs << "image_width" << camera.width;
  fs << "image_height" << camera.height;
  fs << "camera_matrix" << cv::Mat(camera.K());
  fs << "distortion_coefficients" << camera.DistCoeffs();
  fs.release();
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw CameraError(path.string() + ": cannot write here (" + ec.message() + ")");
  }
}

}  // namespace arview::calib
