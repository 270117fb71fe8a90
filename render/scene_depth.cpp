#include "render/scene_depth.h"

#include <Eigen/Geometry>

#include <cmath>
#include <string>

#include "render/offscreen.h"

namespace arview::render {
namespace {

const char* kReceiverVertex = R"(#version 450 core
uniform mat4 mvp;          // projection · view (map → clip)
uniform vec3 corners[4];   // the floor parallelogram, map frame
out vec3 v_world;
void main() {
  const int order[6] = int[6](0, 1, 2, 0, 2, 3);
  v_world = corners[order[gl_VertexID]];
  gl_Position = mvp * vec4(v_world, 1.0);
}
)";

const char* kReceiverFragment = R"(#version 450 core
in vec3 v_world;
uniform mat4 light;         // map → light clip (orthographic)
uniform sampler2D coverage; // the soft coverage in the light view (CastShadow::SetCoverage)
uniform float strength;
out vec4 frag_color;
void main() {
  vec2 uv = (light * vec4(v_world, 1.0)).xy * 0.5 + 0.5;
  float a = strength * textureLod(coverage, uv, 0.0).r;
  // Nothing to darken: 8-bit blending would leave the pixel as it is, so skip it (llvmpipe then
  // skips the blend at every sample of a block with no shadow).
  if (a < 0.5 / 255.0) discard;
  frag_color = vec4(0.0, 0.0, 0.0, a);
}
)";

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
  view->BoundFloor(-1, 1, -1, 1);
  return true;
}

void LightView::BoundFloor(double x0, double x1, double y0, double y1) {
  const double box[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  for (int k = 0; k < 4; ++k) floor_corners[k] = floor_origin + box[k][0] * floor_x + box[k][1] * floor_y;
}

CastShadow::CastShadow(const GlApi& gl) : gl_(&gl) {
  coverage_ = MakeTexture(gl, cv::Mat(kSize, kSize, CV_8UC1, cv::Scalar::all(0)), {false, 1.f, false});
  program_ = MakeProgram(gl, "cast shadow", kReceiverVertex, kReceiverFragment);
  const GLuint p = program_.get();
  mvp_ = Uniform(gl, p, "mvp");
  light_ = Uniform(gl, p, "light");
  corners_ = Uniform(gl, p, "corners");
  strength_ = Uniform(gl, p, "strength");
  coverage_sampler_ = Uniform(gl, p, "coverage");
  vao_ = MakeVertexArray(gl);
  CheckGl(gl, "cast shadow setup");
}

void CastShadow::SetCoverage(const cv::Mat& coverage) {
  if (coverage.size() != cv::Size(kSize, kSize) || coverage.type() != CV_8UC1) {
    throw RenderError("cast shadow: the coverage must be 8-bit, " + std::to_string(kSize) + " x " + std::to_string(kSize));
  }
  UpdateTexture(*gl_, coverage_.get(), coverage);
}

void CastShadow::DrawReceiver(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, const LightView& light,
                              float strength) {
  const GlApi& gl = *gl_;
  const Eigen::Matrix4f mvp = (projection * view).cast<float>();
  const Eigen::Matrix4f to_light = light.map_to_clip.cast<float>();
  float corners[12];
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c) corners[3 * k + c] = static_cast<float>(light.floor_corners[k][c]);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthMask(GL_FALSE);
  gl.Disable(GL_CULL_FACE);
  gl.Enable(GL_BLEND);
  gl.BlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  gl.UseProgram(program_.get());
  gl.UniformMatrix4fv(mvp_, 1, GL_FALSE, mvp.data());
  gl.UniformMatrix4fv(light_, 1, GL_FALSE, to_light.data());
  gl.Uniform3fv(corners_, 4, corners);
  gl.Uniform1f(strength_, strength);
  gl.Uniform1i(coverage_sampler_, 0);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D, coverage_.get());
  gl.BindVertexArray(vao_.get());
  gl.DrawArrays(GL_TRIANGLES, 0, 6);
  gl.BindVertexArray(0);
  gl.Disable(GL_BLEND);
  gl.DepthMask(GL_TRUE);
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
