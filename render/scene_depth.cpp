#include "render/scene_depth.h"

#include <Eigen/Geometry>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "render/offscreen.h"

namespace arview::render {
namespace {

const char* kDepthVertex = R"(#version 450 core
layout(location = 0) in vec3 position;
uniform mat4 mvp;
void main() { gl_Position = mvp * vec4(position, 1.0); }
)";

const char* kDepthFragment = R"(#version 450 core
out vec4 frag_color;
void main() { frag_color = vec4(0.0); }
)";

}  // namespace

bool MakeLightView(const Eigen::Vector3d& towards_light, const Eigen::Vector3d& centre, double radius,
                   const Eigen::Vector3d& floor_point, const Eigen::Vector3d& floor_normal, double min_elevation_deg,
                   LightView* view) {
  const Eigen::Vector3d d = towards_light.normalized();
  const Eigen::Vector3d n = floor_normal.normalized();
  if (!(radius > 0) || d.dot(n) < std::sin(min_elevation_deg * M_PI / 180)) return false;
  // x: the floor normal across the light (a standing character's shadow stretches along it).
  Eigen::Vector3d x = n - n.dot(d) * d;
  x = x.norm() > 1e-6 ? x.normalized() : d.unitOrthogonal();
  const Eigen::Vector3d y = d.cross(x);
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.row(0) << x.transpose() / radius, -x.dot(centre) / radius;
  m.row(1) << y.transpose() / radius, -y.dot(centre) / radius;
  m.row(2) << -d.transpose() / radius, d.dot(centre) / radius;
  m(3, 3) = 1;
  view->map_to_clip = m;
  // Along the light down to the floor: q − d ((q − floor_point) · n / (d · n)), affine in q.
  auto to_floor = [&](const Eigen::Vector3d& q) { return Eigen::Vector3d(q - d * ((q - floor_point).dot(n) / d.dot(n))); };
  view->floor_origin = to_floor(centre);
  view->floor_x = to_floor(centre + radius * x) - view->floor_origin;
  view->floor_y = to_floor(centre + radius * y) - view->floor_origin;
  view->floor_normal = n;
  view->BoundFloor(-1, 1, -1, 1);
  return true;
}

void LightView::BoundFloor(double x0, double x1, double y0, double y1) {
  const double box[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  for (int k = 0; k < 4; ++k) floor_corners[k] = floor_origin + box[k][0] * floor_x + box[k][1] * floor_y;
}

namespace {

// The part of a convex polygon on the positive side of a plane (n · p + d >= 0), in order.
std::vector<Eigen::Vector3d> ClipPolygon(const std::vector<Eigen::Vector3d>& polygon, const Eigen::Vector4d& plane) {
  std::vector<Eigen::Vector3d> out;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& p = polygon[i];
    const Eigen::Vector3d& q = polygon[(i + 1) % polygon.size()];
    const double sp = plane.head<3>().dot(p) + plane.w(), sq = plane.head<3>().dot(q) + plane.w();
    if (sp >= 0) out.push_back(p);
    if ((sp >= 0) != (sq >= 0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
  }
  return out;
}

}  // namespace

void DarkenCastShadow(cv::Mat& frame, const calib::Camera& pinhole, const calib::Pose& pose, double near_m,
                      const LightView& light, const cv::Mat& coverage, float strength,
                      std::span<const Eigen::Vector3f> occluders) {
  const Eigen::Vector3d& n = light.floor_normal;
  const Eigen::Vector3d camera = pose.Center();
  if (!(strength > 0) || n.dot(camera - light.floor_origin) <= 0) return;  // seen from below: none
  // Map → camera as planes in the map frame: in front of the near plane; above the floor.
  const Eigen::Matrix3d r = pose.R();
  const Eigen::Vector4d in_front(r(2, 0), r(2, 1), r(2, 2), pose.t_cw.z() - near_m);
  const Eigen::Vector4d above_floor(n.x(), n.y(), n.z(), -n.dot(light.floor_origin));
  constexpr int kShift = 8;  // sub-pixel bits of the polygon fills
  auto project = [&](const std::vector<Eigen::Vector3d>& polygon, const cv::Point& origin) {
    std::vector<cv::Point> points;
    // In front of the near plane every point is finite; the clamp keeps the fixed-point
    // coordinates of a point just past the near plane within int (only absurd geometry reaches it).
    auto fixed_point = [](double pixel) { return cvRound(std::clamp(pixel, -1e6, 1e6) * (1 << kShift)); };
    for (const Eigen::Vector3d& p : polygon) {
      const Eigen::Vector3d c = pose.ToCamera(p);
      points.emplace_back(fixed_point(pinhole.fx * c.x() / c.z() + pinhole.cx - origin.x),
                          fixed_point(pinhole.fy * c.y() / c.z() + pinhole.cy - origin.y));
    }
    return points;
  };
  const std::vector<Eigen::Vector3d> quad =
      ClipPolygon({light.floor_corners.begin(), light.floor_corners.end()}, in_front);
  if (quad.size() < 3) return;
  std::vector<cv::Point> outline = project(quad, {0, 0});
  const cv::Rect fixed = cv::boundingRect(outline);  // in 1/2^kShift pixels
  const cv::Rect roi = cv::Rect(cv::Point((fixed.x >> kShift) - 1, (fixed.y >> kShift) - 1),
                                cv::Point(((fixed.x + fixed.width) >> kShift) + 2, ((fixed.y + fixed.height) >> kShift) + 2)) &
                       cv::Rect(0, 0, frame.cols, frame.rows);
  if (roi.empty()) return;
  // Where the floor quad is, less where an occluder is above the floor in front of the camera
  // (a point on the ray to a floor point that is above the floor lies between the two).
  cv::Mat inside = cv::Mat::zeros(roi.size(), CV_8U);
  outline = project(quad, roi.tl());
  cv::fillConvexPoly(inside, outline, cv::Scalar(255), cv::LINE_8, kShift);
  for (size_t i = 0; i + 2 < occluders.size(); i += 3) {
    std::vector<Eigen::Vector3d> triangle = {occluders[i].cast<double>(), occluders[i + 1].cast<double>(),
                                             occluders[i + 2].cast<double>()};
    triangle = ClipPolygon(ClipPolygon(triangle, above_floor), in_front);
    if (triangle.size() < 3) continue;
    cv::fillConvexPoly(inside, project(triangle, roi.tl()), cv::Scalar(0), cv::LINE_AA, kShift);
  }
  // Pixel → light clip (x, y) through the floor: the floor point at clip (x, y) projects to
  // K (R (o + x fx + y fy) + t), a homography; its inverse, then clip → texel.
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k << pinhole.fx, 0, pinhole.cx, 0, pinhole.fy, pinhole.cy, 0, 0, 1;
  Eigen::Matrix3d clip_to_pixel;
  clip_to_pixel << r * light.floor_x, r * light.floor_y, r * light.floor_origin + pose.t_cw;
  clip_to_pixel = k * clip_to_pixel;
  const double half = kCastShadowTexels / 2.0;
  Eigen::Matrix3d clip_to_texel;
  clip_to_texel << half, 0, half - 0.5, 0, half, half - 0.5, 0, 0, 1;
  Eigen::Matrix3d roi_to_pixel = Eigen::Matrix3d::Identity();
  roi_to_pixel(0, 2) = roi.x, roi_to_pixel(1, 2) = roi.y;
  const Eigen::Matrix3d roi_to_texel = clip_to_texel * clip_to_pixel.inverse() * roi_to_pixel;
  // Bilinear, 0 outside the texture, over the pixels inside the quad: for the bench's tube 25k
  // (42k pixels in the rectangle, 20k inside) 0.36 ms, where cv::warpPerspective of the whole
  // rectangle and then a darkening pass took 0.42 + 0.14 ms.
  const Eigen::Matrix3f h = roi_to_texel.cast<float>();
  const int cols = coverage.cols, rows = coverage.rows;
  cv::Mat padded;  // a border of zeros: the four taps of any (u, v) in (−1, size) need no checks
  cv::copyMakeBorder(coverage, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  const float gain = std::clamp(strength, 0.f, 1.f) / 255.f;  // alpha (0..255) per coverage x inside level
  for (int y = 0; y < roi.height; ++y) {
    const std::uint8_t* q = inside.ptr<std::uint8_t>(y);
    cv::Vec3b* bg = frame.ptr<cv::Vec3b>(roi.y + y) + roi.x;
    Eigen::Vector3f t = h.col(1) * static_cast<float>(y) + h.col(2);
    for (int x = 0; x < roi.width; ++x, t += h.col(0)) {
      if (q[x] == 0) continue;
      const float w = 1 / t.z();
      const float u = t.x() * w + 1, v = t.y() * w + 1;  // in the padded texture
      if (!(u > 0 && v > 0 && u < cols + 1 && v < rows + 1)) continue;
      const int c0 = static_cast<int>(u), r0 = static_cast<int>(v);
      const float fu = u - c0, fv = v - r0;
      const std::uint8_t* top = padded.ptr<std::uint8_t>(r0) + c0;
      const std::uint8_t* bottom = top + padded.step[0];
      const float c = (1 - fv) * ((1 - fu) * top[0] + fu * top[1]) + fv * ((1 - fu) * bottom[0] + fu * bottom[1]);
      // alpha (0..255) = strength × coverage × inside, rounded as the 8-bit layer was.
      const int a = static_cast<int>(c * q[x] * gain + 0.5f);
      if (a == 0) continue;
      const int keep = 255 - a;
      for (int ch = 0; ch < 3; ++ch) bg[x][ch] = static_cast<std::uint8_t>((bg[x][ch] * keep + 127) / 255);
    }
  }
}

DepthProxy::DepthProxy(const GlApi& gl, const std::vector<Eigen::Vector3f>& triangles) : gl_(&gl) {
  program_ = MakeProgram(gl, "depth proxy", kDepthVertex, kDepthFragment);
  mvp_ = Uniform(gl, program_.get(), "mvp");
  count_ = static_cast<GLsizei>(triangles.size() / 3 * 3);
  triangles_.assign(triangles.begin(), triangles.begin() + count_);
  vao_ = MakeVertexArray(gl);
  gl.BindVertexArray(vao_.get());
  vbo_ = MakeBuffer(gl, GL_ARRAY_BUFFER, triangles.data(), std::max<size_t>(1, count_) * sizeof(Eigen::Vector3f));
  const std::uint32_t none = 0;
  ibo_ = MakeBuffer(gl, GL_ELEMENT_ARRAY_BUFFER, &none, sizeof none);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Eigen::Vector3f), nullptr);
  gl.BindVertexArray(0);
  CheckGl(gl, "depth proxy upload");
}

void DepthProxy::Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, double farthest) {
  drawn_ = 0;
  if (count_ == 0) return;
  // OpenGL's camera looks down −z: the distance along the view axis is −z.
  const Eigen::RowVector4f depth_row = -view.row(2).cast<float>();
  const float limit = static_cast<float>(std::min(farthest, 1e30));
  indices_.clear();
  for (GLsizei i = 0; i < count_; i += 3) {
    bool nearer = false;
    for (int k = 0; k < 3; ++k) nearer = nearer || depth_row.dot(triangles_[i + k].homogeneous()) < limit;
    if (!nearer) continue;
    for (int k = 0; k < 3; ++k) indices_.push_back(static_cast<std::uint32_t>(i + k));
  }
  drawn_ = static_cast<GLsizei>(indices_.size());
  if (drawn_ == 0) return;
  const GlApi& gl = *gl_;
  const Eigen::Matrix4f mvp = (projection * view).cast<float>();
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  gl.DepthMask(GL_TRUE);
  gl.Disable(GL_CULL_FACE);
  gl.Disable(GL_BLEND);
  gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  gl.UseProgram(program_.get());
  gl.UniformMatrix4fv(mvp_, 1, GL_FALSE, mvp.data());
  gl.BindVertexArray(vao_.get());
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_.get());
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices_.size() * sizeof(std::uint32_t)), indices_.data(),
                GL_STREAM_DRAW);
  gl.DrawElements(GL_TRIANGLES, drawn_, GL_UNSIGNED_INT, nullptr);
  gl.BindVertexArray(0);
  gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

}  // namespace arview::render
