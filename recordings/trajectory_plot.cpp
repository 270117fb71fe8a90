// PlotTrajectories (accuracy.h): two orthographic views drawn with OpenCV.

#include "base/image_file.h"

#include "base/stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recordings/accuracy.h"

namespace arview::recordings {

namespace {

// Orthonormal axes of the ground-truth path, largest spread first. The path of a handheld or
// orbiting camera lies mostly in its first two axes, so (e1, e2) is a "top" view and (e1, e3)
// a "side" view whatever the world's up direction is.
Eigen::Matrix3d PrincipalAxes(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 3) return Eigen::Matrix3d::Identity();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(2) > 0)) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d axes;  // columns e1, e2, e3 (eigenvalues come in increasing order)
  axes.col(0) = eig.eigenvectors().col(2);
  axes.col(1) = eig.eigenvectors().col(1);
  axes.col(2) = axes.col(0).cross(axes.col(1));
  return axes;
}

cv::Scalar ErrorColour(double error, double max_error) {
  static const cv::Mat lut = [] {
    cv::Mat ramp(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) ramp.at<uchar>(i) = static_cast<uchar>(i);
    cv::Mat colours;
    cv::applyColorMap(ramp, colours, cv::COLORMAP_JET);
    return colours;
  }();
  const double f = max_error > 0 ? std::clamp(error / max_error, 0.0, 1.0) : 0.0;
  const cv::Vec3b c = lut.at<cv::Vec3b>(0, static_cast<int>(std::lround(f * 255)));
  return {double(c[0]), double(c[1]), double(c[2])};
}

struct Panel {
  cv::Rect area;
  int u_axis, v_axis;  // indices into the principal axes
  const char* title;
};

std::string Format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

}  // namespace

void PlotTrajectories(const AccuracyReport& report, const Trajectory& groundtruth, const std::filesystem::path& png,
                      int width, int height) {
  if (width < 200 || height < 150) throw RecordingError(png.string() + ": plot size too small");
  std::vector<Eigen::Vector3d> gt_points;
  for (const StampedPose& p : groundtruth) gt_points.push_back(p.pose.Center());
  const Eigen::Matrix3d axes = PrincipalAxes(gt_points);
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const auto& p : gt_points) origin += p;
  if (!gt_points.empty()) origin /= static_cast<double>(gt_points.size());
  auto coords = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d { return axes.transpose() * (p - origin); };

  // One scale for both panels, from the ground truth and the associated estimates.
  std::vector<Eigen::Vector3d> shown;
  for (const auto& p : gt_points) shown.push_back(coords(p));
  for (const auto& [i, j] : report.pairs) shown.push_back(coords(report.aligned_estimate[i].pose.Center()));
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(-1e-9), hi = Eigen::Vector3d::Constant(1e-9);
  for (const auto& c : shown) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const int header = 40, footer = 50, margin = 30;
  const int panel_w = width / 2;
  const int panel_h = height - header - footer;
  const Panel panels[2] = {{cv::Rect(0, header, panel_w, panel_h), 0, 1, "top view (axes 1-2 of the path)"},
                           {cv::Rect(panel_w, header, panel_w, panel_h), 0, 2, "side view (axes 1-3 of the path)"}};
  double scale = 1e300;
  for (const Panel& p : panels) {
    const double su = (p.area.width - 2 * margin) / (hi[p.u_axis] - lo[p.u_axis]);
    const double sv = (p.area.height - 2 * margin) / (hi[p.v_axis] - lo[p.v_axis]);
    scale = std::min({scale, su, sv});
  }

  // Consecutive ground-truth poses are joined only when they are near neighbours: still-image
  // data sets (templeRing) list views out of path order, and long chords would mislead.
  std::vector<double> steps;
  for (size_t k = 1; k < gt_points.size(); ++k) steps.push_back((gt_points[k] - gt_points[k - 1]).norm());
  std::vector<bool> joined(gt_points.size(), false);
  if (!steps.empty()) {
    const double limit = 3 * Median(steps);
    for (size_t k = 1; k < gt_points.size(); ++k) joined[k] = steps[k - 1] <= limit;
  }

  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const double max_error = std::max(report.ate.max, 1e-12);
  for (const Panel& p : panels) {
    const double cu = 0.5 * (lo[p.u_axis] + hi[p.u_axis]), cv_ = 0.5 * (lo[p.v_axis] + hi[p.v_axis]);
    auto pixel = [&](const Eigen::Vector3d& world) {
      const Eigen::Vector3d c = coords(world);
      return cv::Point2d(p.area.x + p.area.width / 2.0 + (c[p.u_axis] - cu) * scale,
                         p.area.y + p.area.height / 2.0 - (c[p.v_axis] - cv_) * scale);
    };
    const int shift = 4;  // sub-pixel drawing
    auto fixed = [&](const cv::Point2d& q) { return cv::Point(int(std::lround(q.x * 16)), int(std::lround(q.y * 16))); };
    cv::rectangle(image, p.area, cv::Scalar(200, 200, 200), 1);
    cv::putText(image, p.title, {p.area.x + 8, p.area.y + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {60, 60, 60}, 1,
                cv::LINE_AA);
    for (size_t k = 1; k < groundtruth.size(); ++k) {
      if (!joined[k]) continue;
      cv::line(image, fixed(pixel(groundtruth[k - 1].pose.Center())), fixed(pixel(groundtruth[k].pose.Center())),
               {150, 150, 150}, 1, cv::LINE_AA, shift);
    }
    for (const StampedPose& g : groundtruth) {
      cv::circle(image, fixed(pixel(g.pose.Center())), 2 * 16, {120, 120, 120}, -1, cv::LINE_AA, shift);
    }
    for (size_t k = 0; k < report.pairs.size(); ++k) {
      const auto [i, j] = report.pairs[k];
      const cv::Scalar colour = ErrorColour(report.position_errors[k], max_error);
      const cv::Point2d e = pixel(report.aligned_estimate[i].pose.Center());
      cv::line(image, fixed(pixel(groundtruth[j].pose.Center())), fixed(e), colour, 1, cv::LINE_AA, shift);
      cv::circle(image, fixed(e), 3 * 16, colour, -1, cv::LINE_AA, shift);
    }
  }

  const std::string headline = "ATE rmse " + Format("%.4g", report.ate.rmse) + "  median " +
                               Format("%.4g", report.ate.median) + "  max " + Format("%.4g", report.ate.max) +
                               "  (" + ToString(report.align) + " alignment)  coverage " +
                               Format("%.1f%%", 100.0 * report.coverage);
  cv::putText(image, headline, {10, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 1, cv::LINE_AA);
  // Colour bar: estimate error from 0 to the maximum.
  const int bar_x = 10, bar_y = height - footer + 12, bar_w = std::min(400, width - 200), bar_h = 14;
  for (int x = 0; x < bar_w; ++x) {
    cv::line(image, {bar_x + x, bar_y}, {bar_x + x, bar_y + bar_h}, ErrorColour(double(x) / (bar_w - 1), 1.0), 1);
  }
  cv::putText(image, "0", {bar_x, bar_y + bar_h + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1, cv::LINE_AA);
  cv::putText(image, Format("%.4g", report.ate.max), {bar_x + bar_w - 40, bar_y + bar_h + 16},
              cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1, cv::LINE_AA);
  cv::putText(image, "estimate position error (grey: ground truth)", {bar_x + bar_w + 12, bar_y + bar_h - 2},
              cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1, cv::LINE_AA);

  WriteImageAtomically(png, image);
}

}  // namespace arview::recordings
