#include "tracker/rotation_aligner.h"

#include <Eigen/Cholesky>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "tracker/working_resolution.h"

namespace arview::tracker {
namespace {

// Huber's threshold on the intensity difference of the normalised images (their standard
// deviation is 1): differences beyond half a standard deviation are outliers' more than noise.
constexpr double kHuberThreshold = 0.5;
constexpr double kConvergedRadians = 1e-6;

float Bilinear(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x0 + 1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x0 + 1]);
}

// Where the current level sees the reference pixel's bearing under `R`; false outside the image
// (with the one pixel bilinear sampling needs) or behind the camera.
bool Warp(const SmallImage::Level& level, const Eigen::Matrix3d& R, const Eigen::Vector3d& bearing,
          Eigen::Vector3d* p, Eigen::Vector2d* u) {
  const calib::Camera& camera = level.camera;
  *p = R * bearing;
  if (p->z() < 1e-6) return false;
  const double xn = p->x() / p->z(), yn = p->y() / p->z();
  if (xn * xn + yn * yn > level.max_radius2) return false;
  *u = camera.Project(*p);
  return u->x() >= 0 && u->y() >= 0 && u->x() < camera.width - 1 && u->y() < camera.height - 1;
}

struct LevelPixels {  // the reference level's pixels: bearing and intensity
  std::vector<Eigen::Vector3d> bearings;
  std::vector<float> intensities;
};

LevelPixels ReferencePixels(const SmallImage::Level& level) {
  LevelPixels out;
  const int w = level.image.cols, h = level.image.rows;
  out.bearings.reserve(static_cast<size_t>(w * h));
  out.intensities.reserve(static_cast<size_t>(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      out.bearings.push_back(level.camera.Unproject({double(x), double(y)}));
      out.intensities.push_back(level.image.at<float>(y, x));
    }
  return out;
}

// One Gauss-Newton step on the level; the rotation increment (radians, current camera's axes).
Eigen::Vector3d GaussNewtonStep(const LevelPixels& ref, const SmallImage::Level& cur, const Eigen::Matrix3d& R) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  const double fx = cur.camera.fx, fy = cur.camera.fy;
  for (size_t i = 0; i < ref.bearings.size(); ++i) {
    Eigen::Vector3d p;
    Eigen::Vector2d u;
    if (!Warp(cur, R, ref.bearings[i], &p, &u)) continue;
    const double r = Bilinear(cur.image, u.x(), u.y()) - ref.intensities[i];
    const double gx = Bilinear(cur.grad_x, u.x(), u.y()), gy = Bilinear(cur.grad_y, u.x(), u.y());
    // d(pixel)/d(p) of the pinhole part (distortion is small at this scale and only slows the
    // steps, not the minimum), times d(p)/d(delta) = -[p]x for R <- exp(delta) R.
    const double iz = 1.0 / p.z(), xn = p.x() * iz, yn = p.y() * iz;
    const Eigen::Vector3d dI_dp(gx * fx * iz, gy * fy * iz, -(gx * fx * xn + gy * fy * yn) * iz);
    const Eigen::Vector3d J = p.cross(dI_dp);  // (dI/dp) · (-[p]x) as a row: -(dI/dp)ᵀ[p]x = (p × dI/dp)ᵀ
    const double weight = std::abs(r) <= kHuberThreshold ? 1.0 : kHuberThreshold / std::abs(r);
    H += weight * J * J.transpose();
    g += weight * J * r;
  }
  if (H.determinant() < 1e-12) return Eigen::Vector3d::Zero();
  return -H.ldlt().solve(g);
}

// Zero-mean normalised cross-correlation of the reference's pixels and the current level's
// intensities where `R` puts them, and the fraction of pixels compared.
void Correlate(const LevelPixels& ref, const SmallImage::Level& cur, const Eigen::Matrix3d& R, double* zncc,
               double* overlap) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  int n = 0;
  for (size_t i = 0; i < ref.bearings.size(); ++i) {
    Eigen::Vector3d p;
    Eigen::Vector2d u;
    if (!Warp(cur, R, ref.bearings[i], &p, &u)) continue;
    const double a = ref.intensities[i], b = Bilinear(cur.image, u.x(), u.y());
    sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
    ++n;
  }
  *overlap = ref.bearings.empty() ? 0.0 : static_cast<double>(n) / static_cast<double>(ref.bearings.size());
  *zncc = 0;
  if (n < 2) return;
  const double cov = sab - sa * sb / n, va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (va > 0 && vb > 0) *zncc = cov / std::sqrt(va * vb);
}

}  // namespace

SmallImage::SmallImage(const cv::Mat& gray, const calib::Camera& camera, const RotationAlignerOptions& options) {
  if (gray.empty() || gray.type() != CV_8U || options.long_side < 8 || options.levels < 1) return;
  const double longest = std::max(gray.cols, gray.rows);
  for (int k = 0; k < options.levels; ++k) {
    const double scale = options.long_side / std::pow(2.0, k) / longest;
    const int w = std::max(4, static_cast<int>(std::lround(gray.cols * scale)));
    const int h = std::max(4, static_cast<int>(std::lround(gray.rows * scale)));
    Level level;
    cv::Mat small;
    cv::resize(gray, small, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    small.convertTo(level.image, CV_32F);
    if (options.blur_sigma > 0) cv::GaussianBlur(level.image, level.image, cv::Size(), options.blur_sigma);
    cv::Scalar mean, stddev;
    cv::meanStdDev(level.image, mean, stddev);
    if (k == 0) contrast_ = stddev[0];
    level.image = (level.image - mean[0]) / std::max(stddev[0], 1e-6);
    cv::Sobel(level.image, level.grad_x, CV_32F, 1, 0, 1, 0.5);
    cv::Sobel(level.image, level.grad_y, CV_32F, 0, 1, 1, 0.5);
    level.camera = ScaleCamera(camera, w, h);
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(w - 1, 0), Eigen::Vector2d(0, h - 1),
                                         Eigen::Vector2d(w - 1, h - 1)}) {
      const Eigen::Vector3d b = level.camera.Unproject(corner);
      level.max_radius2 = std::max(level.max_radius2, (b.x() * b.x() + b.y() * b.y()) / (b.z() * b.z()));
    }
    levels_.push_back(std::move(level));
  }
}

RotationAlignment AlignRotation(const SmallImage& reference, const SmallImage& current,
                                const Eigen::Quaterniond& initial, const RotationAlignerOptions& options) {
  RotationAlignment out;
  if (reference.empty() || current.empty() || reference.levels().size() != current.levels().size()) {
    out.reason = "no small images to align";
    return out;
  }
  if (std::min(reference.contrast(), current.contrast()) < options.min_contrast) {
    std::ostringstream msg;
    msg << "image alignment: contrast " << std::min(reference.contrast(), current.contrast())
        << " grey levels, at least " << options.min_contrast << " needed";
    out.reason = msg.str();
    return out;
  }
  Eigen::Matrix3d R = initial.normalized().toRotationMatrix();
  LevelPixels finest;
  for (int k = static_cast<int>(reference.levels().size()) - 1; k >= 0; --k) {
    LevelPixels ref = ReferencePixels(reference.levels()[k]);
    for (int it = 0; it < options.max_iterations; ++it) {
      const Eigen::Vector3d delta = GaussNewtonStep(ref, current.levels()[k], R);
      ++out.iterations;
      if (!delta.allFinite()) break;
      R = Eigen::AngleAxisd(delta.norm(), delta.norm() > 0 ? delta.normalized() : Eigen::Vector3d::UnitZ())
              .toRotationMatrix() * R;
      if (delta.norm() < kConvergedRadians) break;
    }
    if (k == 0) finest = std::move(ref);  // kept for the correlation below
  }
  out.rotation = Eigen::Quaterniond(R).normalized();
  Correlate(finest, current.levels()[0], R, &out.zncc, &out.overlap);
  std::ostringstream msg;
  if (out.overlap < options.min_overlap) {
    msg << "image alignment: the frames share " << out.overlap << " of the view, at least " << options.min_overlap
        << " needed";
  } else if (out.zncc < options.min_zncc) {
    msg << "image alignment: correlation " << out.zncc << ", at least " << options.min_zncc << " needed";
  }
  out.reason = msg.str();
  out.ok = out.reason.empty();
  return out;
}

}  // namespace arview::tracker
