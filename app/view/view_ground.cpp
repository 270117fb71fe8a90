#include "app/view/view_ground.h"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

namespace arview::app {

namespace {

constexpr double kNear = 1e-3;
const cv::Scalar kSky(52, 44, 40), kFloor(70, 66, 62), kLine(108, 104, 100), kAxis(150, 120, 60), kForward(60, 170, 230);

cv::Point2d Project(const calib::Camera& camera, const Eigen::Vector3d& c) {
  return {camera.fx * c.x() / c.z() + camera.cx, camera.fy * c.y() / c.z() + camera.cy};
}

// Sub-pixel points for cv::line/fillPoly (shift = 4 bits).
cv::Point Fixed(const cv::Point2d& p) {
  auto clamp = [](double v) { return std::max(-1e6, std::min(1e6, v)); };
  return {static_cast<int>(std::lround(clamp(p.x) * 16)), static_cast<int>(std::lround(clamp(p.y) * 16))};
}

void DrawSegment(cv::Mat& image, const calib::Camera& camera, const calib::Pose& pose, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, const cv::Scalar& colour, int thickness) {
  Eigen::Vector3d ca = pose.ToCamera(a), cb = pose.ToCamera(b);
  if (ca.z() < kNear && cb.z() < kNear) return;
  if (ca.z() < kNear) ca = ca + (cb - ca) * ((kNear - ca.z()) / (cb.z() - ca.z()));
  if (cb.z() < kNear) cb = cb + (ca - cb) * ((kNear - cb.z()) / (ca.z() - cb.z()));
  cv::line(image, Fixed(Project(camera, ca)), Fixed(Project(camera, cb)), colour, thickness, cv::LINE_AA, 4);
}

// Sutherland–Hodgman against the near plane, in camera coordinates.
std::vector<Eigen::Vector3d> ClipNear(const std::vector<Eigen::Vector3d>& polygon) {
  std::vector<Eigen::Vector3d> out;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& p = polygon[i];
    const Eigen::Vector3d& q = polygon[(i + 1) % polygon.size()];
    const bool p_in = p.z() >= kNear, q_in = q.z() >= kNear;
    if (p_in) out.push_back(p);
    if (p_in != q_in) out.push_back(p + (q - p) * ((kNear - p.z()) / (q.z() - p.z())));
  }
  return out;
}

}  // namespace

double GridCellFor(double character_height) {
  if (!(character_height > 0) || !std::isfinite(character_height)) return 1;
  const double target = character_height / 2;
  const double decade = std::pow(10.0, std::floor(std::log10(target)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= target / 1.6) return m * decade;
  }
  return 10 * decade;
}

cv::Mat RenderGround(const GroundGrid& grid, const calib::Camera& camera, const calib::Pose& pose) {
  cv::Mat image(camera.Size(), CV_8UC3, kSky);
  const Eigen::Vector3d up = grid.up.normalized();
  Eigen::Vector3d f = grid.forward - grid.forward.dot(up) * up;
  if (f.norm() < 1e-9) f = up.unitOrthogonal();
  f.normalize();
  const Eigen::Vector3d s = up.cross(f);
  const double extent = grid.cell * grid.half_cells;
  const bool above = up.dot(pose.Center() - grid.origin) > 0;

  std::vector<Eigen::Vector3d> quad;
  for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    quad.push_back(pose.ToCamera(grid.origin + extent * (a * f + b * s)));
  }
  const std::vector<Eigen::Vector3d> visible = ClipNear(quad);
  if (visible.size() >= 3) {
    std::vector<cv::Point> pts;
    for (const Eigen::Vector3d& c : visible) pts.push_back(Fixed(Project(camera, c)));
    cv::fillPoly(image, std::vector<std::vector<cv::Point>>{pts}, above ? kFloor : kSky * 0.8, cv::LINE_AA, 4);
  }
  for (int i = -grid.half_cells; i <= grid.half_cells; ++i) {
    const double o = i * grid.cell;
    const bool axis = i == 0;
    DrawSegment(image, camera, pose, grid.origin + o * s - extent * f, grid.origin + o * s + extent * f,
                axis ? kAxis : kLine, 1);
    DrawSegment(image, camera, pose, grid.origin + o * f - extent * s, grid.origin + o * f + extent * s,
                axis ? kAxis : kLine, 1);
  }
  // The character's forward: from its feet to the grid's edge.
  DrawSegment(image, camera, pose, grid.origin, grid.origin + extent * f, kForward, 2);
  return image;
}

}  // namespace arview::app
