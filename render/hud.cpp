#include "render/hud.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arview::render {

namespace {

constexpr double kDeg = M_PI / 180;
const cv::Scalar kRed(40, 40, 235), kWhite(255, 255, 255), kBlack(0, 0, 0);
const cv::Scalar kWireFront(200, 200, 200), kWireBack(110, 110, 110), kWireForward(60, 170, 230);

struct Style {
  double font_scale;
  int line_height;
  int dot_radius;
};

Style StyleFor(const cv::Mat& frame) {
  const double s = std::clamp(frame.rows / 720.0, 0.6, 1.5);
  return {0.45 * s, static_cast<int>(std::lround(18 * s)), std::max(4, static_cast<int>(std::lround(7 * s)))};
}

cv::Point Fixed(const cv::Point2d& p) {
  auto clamp = [](double v) { return std::max(-1e6, std::min(1e6, v)); };
  return {static_cast<int>(std::lround(clamp(p.x) * 16)), static_cast<int>(std::lround(clamp(p.y) * 16))};
}

cv::Point Rounded(const cv::Point2d& p) { return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))}; }

Eigen::Vector3d ToMap(const HudSphere& s, const Eigen::Vector3d& direction) {
  return s.centre + s.radius * (s.rotation * direction.normalized());
}

bool Project(const calib::Camera& camera, const calib::Pose& pose, const Eigen::Vector3d& world, cv::Point2d* px) {
  const Eigen::Vector3d c = pose.ToCamera(world);
  if (c.z() < 1e-6) return false;
  *px = {camera.fx * c.x() / c.z() + camera.cx, camera.fy * c.y() / c.z() + camera.cy};
  return true;
}

// Whether a point of the sphere faces the camera (on the near hemisphere as seen from it).
bool FacesCamera(const HudSphere& s, const Eigen::Vector3d& world, const Eigen::Vector3d& camera_centre) {
  return (world - s.centre).dot(camera_centre - world) > 0;
}

Eigen::Vector3d Direction(const HudSphere& s, double azimuth_deg, double elevation_deg) {
  const Eigen::Vector3d up = s.up.normalized();
  Eigen::Vector3d f = s.forward - s.forward.dot(up) * up;
  if (f.norm() < 1e-9) f = up.unitOrthogonal();
  f.normalize();
  const Eigen::Vector3d left = up.cross(f);
  const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
  return std::cos(e) * (std::cos(a) * f + std::sin(a) * left) + std::sin(e) * up;
}

// A circle of the globe sampled every 7.5°, each piece shaded by the side it is on.
template <typename DirectionAt>
void DrawWire(cv::Mat& frame, const HudSphere& s, const calib::Camera& camera, const calib::Pose& pose,
              DirectionAt direction_at, double from, double to, const cv::Scalar& front_colour) {
  const Eigen::Vector3d eye = pose.Center();
  const int steps = std::max(2, static_cast<int>(std::ceil((to - from) / 7.5)));
  Eigen::Vector3d prev = ToMap(s, direction_at(from));
  for (int i = 1; i <= steps; ++i) {
    const Eigen::Vector3d next = ToMap(s, direction_at(from + (to - from) * i / steps));
    cv::Point2d a, b;
    if (Project(camera, pose, prev, &a) && Project(camera, pose, next, &b)) {
      const bool front = FacesCamera(s, (prev + next) / 2, eye);
      cv::line(frame, Fixed(a), Fixed(b), front ? front_colour : kWireBack, 1, cv::LINE_AA, 4);
    }
    prev = next;
  }
}

// Over the scene, a dark outline keeps text legible on any background; on a darkened panel
// it is not needed (and text is most of the overlay's cost).
void DrawText(cv::Mat& frame, const std::string& text, cv::Point origin, double scale, const cv::Scalar& colour,
              bool outline = true) {
  if (outline) cv::putText(frame, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, kBlack, 3, cv::LINE_AA);
  cv::putText(frame, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

void Darken(cv::Mat& frame, cv::Rect rect) {
  rect &= cv::Rect(0, 0, frame.cols, frame.rows);
  if (rect.empty()) return;
  cv::Mat roi = frame(rect);
  roi.convertTo(roi, -1, 0.45);
}

std::string WeightText(double w) {
  char t[16];
  std::snprintf(t, sizeof t, "%.3f", w);
  return t;
}

void DrawSphere(cv::Mat& frame, const calib::Camera& camera, const calib::Pose& pose, const HudSphere& s,
                const Style& style) {
  for (double elevation : {-45.0, 0.0, 45.0}) {
    DrawWire(frame, s, camera, pose, [&](double a) { return Direction(s, a, elevation); }, -180, 180, kWireFront);
  }
  for (int azimuth = 0; azimuth < 360; azimuth += 45) {
    DrawWire(frame, s, camera, pose, [&](double e) { return Direction(s, azimuth, e); }, -90, 90,
             azimuth == 0 ? kWireForward : kWireFront);
  }
  const Eigen::Vector3d eye = pose.Center();
  // Far keys first, so that near ones are drawn over them.
  std::vector<int> order(s.keys.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  auto depth = [&](int k) { return pose.ToCamera(ToMap(s, s.keys[k].direction)).z(); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return depth(a) > depth(b); });
  for (int k : order) {
    const HudKey& key = s.keys[k];
    const Eigen::Vector3d world = ToMap(s, key.direction);
    cv::Point2d px;
    if (!Project(camera, pose, world, &px)) continue;
    const bool front = FacesCamera(s, world, eye);
    const int r = front ? style.dot_radius : std::max(3, style.dot_radius * 2 / 3);
    cv::circle(frame, Fixed(px), r * 16, WeightColour(key.weight), cv::FILLED, cv::LINE_AA, 4);
    cv::circle(frame, Fixed(px), r * 16, key.highlighted ? kWhite : kBlack, key.highlighted ? 2 : 1, cv::LINE_AA, 4);
    DrawText(frame, std::to_string(k) + " " + key.label + " " + WeightText(key.weight),
             Rounded(px) + cv::Point(r + 3, -r), style.font_scale * (front ? 1.0 : 0.85), front ? kWhite : kWireFront);
  }
  cv::Point2d centre_px, view_px;
  const Eigen::Vector3d view_world = ToMap(s, s.viewpoint);
  if (Project(camera, pose, view_world, &view_px)) {
    if (Project(camera, pose, s.centre, &centre_px)) cv::line(frame, Fixed(centre_px), Fixed(view_px), kRed, 1, cv::LINE_AA, 4);
    const int r = std::max(3, style.dot_radius * 3 / 4);
    cv::circle(frame, Fixed(view_px), r * 16, kRed, cv::FILLED, cv::LINE_AA, 4);
    cv::circle(frame, Fixed(view_px), r * 16, kWhite, 1, cv::LINE_AA, 4);
  }
}

// The weights of the first sphere's keys as bars, top right.
void DrawWeightPanel(cv::Mat& frame, const HudSphere& s, const Style& style) {
  const int rows = static_cast<int>(s.keys.size()) + 1;
  const int width = static_cast<int>(260 * style.font_scale / 0.45);
  const int bar = static_cast<int>(80 * style.font_scale / 0.45);
  const cv::Rect panel(frame.cols - width - 10, 10, width, rows * style.line_height + 10);
  Darken(frame, panel);
  int y = panel.y + style.line_height;
  DrawText(frame, s.name + ": " + std::to_string(s.keys.size()) + " keys", {panel.x + 6, y}, style.font_scale, kWhite,
           false);
  for (size_t k = 0; k < s.keys.size(); ++k) {
    y += style.line_height;
    const HudKey& key = s.keys[k];
    const int x0 = panel.x + 6;
    cv::rectangle(frame, cv::Rect(x0, y - style.line_height + 6, bar, style.line_height - 8), kWireBack, 1);
    cv::rectangle(frame,
                  cv::Rect(x0, y - style.line_height + 6, std::max(1, static_cast<int>(std::lround(bar * key.weight))),
                           style.line_height - 8),
                  WeightColour(key.weight), cv::FILLED);
    DrawText(frame, std::to_string(k) + " " + key.label + " " + WeightText(key.weight), {x0 + bar + 6, y},
             style.font_scale, key.highlighted ? cv::Scalar(120, 255, 255) : kWhite, false);
  }
}

void DrawLines(cv::Mat& frame, const std::vector<std::string>& lines, bool bottom, const Style& style) {
  if (lines.empty()) return;
  int width = 0;
  for (const std::string& l : lines) {
    int base = 0;
    width = std::max(width, cv::getTextSize(l, cv::FONT_HERSHEY_SIMPLEX, style.font_scale, 1, &base).width);
  }
  const int height = static_cast<int>(lines.size()) * style.line_height + 8;
  const cv::Rect box(8, bottom ? frame.rows - height - 8 : 8, width + 14, height);
  Darken(frame, box);
  int y = box.y + style.line_height - 2;
  for (const std::string& l : lines) {
    DrawText(frame, l, {box.x + 7, y}, style.font_scale, kWhite, false);
    y += style.line_height;
  }
}

}  // namespace

std::string EyeContactLine(const anim::GazeFrame& eyes) {
  if (!eyes.active) return {};
  return std::string(eyes.eyes_on_viewer ? "eye contact" : "eyes away") + (eyes.blinking ? "  (blink)" : "");
}

cv::Scalar WeightColour(double weight) {
  // Dark blue → green → yellow (BGR), a ramp that stays readable on grey floors and video.
  const double w = std::clamp(std::isfinite(weight) ? weight : 0.0, 0.0, 1.0);
  if (w < 0.5) {
    const double t = w / 0.5;
    return {200 * (1 - t) + 40 * t, 60 * (1 - t) + 200 * t, 20 * (1 - t) + 40 * t};
  }
  const double t = (w - 0.5) / 0.5;
  return {40 * (1 - t) + 30 * t, 200 * (1 - t) + 240 * t, 40 * (1 - t) + 250 * t};
}

bool ProjectOnSphere(const HudSphere& sphere, const Eigen::Vector3d& direction, const calib::Camera& camera,
                     const calib::Pose& pose, cv::Point2d* pixel) {
  return Project(camera, pose, ToMap(sphere, direction), pixel);
}

void DrawHud(cv::Mat& frame, const calib::Camera& camera, const calib::Pose& pose,
             const std::vector<HudSphere>& spheres, const HudText& text) {
  if (frame.empty() || frame.type() != CV_8UC3) return;
  const Style style = StyleFor(frame);
  for (const HudSphere& s : spheres) DrawSphere(frame, camera, pose, s, style);
  if (!spheres.empty()) DrawWeightPanel(frame, spheres.front(), style);
  DrawLines(frame, text.status, false, style);
  DrawLines(frame, text.help, true, style);
}

HudSphere HudSphereFor(const anim::Placement& placement, const std::string& name,
                       std::span<const Eigen::Vector3d> key_directions, std::span<const std::string> key_labels,
                       std::span<const double> weights, const Eigen::Vector3d& viewpoint, double height,
                       int highlighted_key) {
  HudSphere s;
  s.name = name;
  s.centre = placement.anchor.position;
  s.rotation = placement.anchor.rotation.normalized();
  s.forward = placement.forward;
  s.up = placement.up;
  s.radius = 1.1 * height;
  s.viewpoint = viewpoint;
  for (size_t k = 0; k < key_directions.size(); ++k) {
    HudKey key;
    key.direction = key_directions[k];
    key.weight = k < weights.size() ? weights[k] : 0;
    key.label = k < key_labels.size() ? key_labels[k] : std::string();
    key.highlighted = static_cast<int>(k) == highlighted_key;
    s.keys.push_back(key);
  }
  return s;
}

}  // namespace arview::render
