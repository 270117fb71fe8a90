#include "render/textured_scene.h"

#include <cstddef>
#include <string>

#include "render/offscreen.h"

namespace arview::render {
namespace {

const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec2 uv;
layout(location = 2) in vec3 color;
uniform mat4 mvp;
out vec2 v_uv;
out vec3 v_color;
void main() {
  v_uv = uv;
  v_color = color;
  gl_Position = mvp * vec4(position, 1.0);
}
)";

const char* kFragmentShader = R"(#version 450 core
in vec2 v_uv;
in vec3 v_color;
uniform sampler2D albedo;
out vec4 frag_color;
void main() {
  frag_color = vec4(texture(albedo, v_uv).rgb * v_color, 1.0);
}
)";

SceneVertex Vertex(const Eigen::Vector3d& p, float u, float v, const Eigen::Vector3f& c) {
  return {{float(p.x()), float(p.y()), float(p.z())}, {u, v}, {c.x(), c.y(), c.z()}};
}

}  // namespace

void AppendQuad(TriangleBatch& batch, const Eigen::Vector3d corners[4], const Eigen::Vector4f& uv,
                const Eigen::Vector3f& color) {
  const SceneVertex tl = Vertex(corners[0], uv[0], uv[1], color);
  const SceneVertex tr = Vertex(corners[1], uv[2], uv[1], color);
  const SceneVertex br = Vertex(corners[2], uv[2], uv[3], color);
  const SceneVertex bl = Vertex(corners[3], uv[0], uv[3], color);
  batch.vertices.insert(batch.vertices.end(), {tl, bl, br, tl, br, tr});
}

TexturedScene::TexturedScene(const GlApi& gl, const std::vector<cv::Mat>& textures,
                             const std::vector<TriangleBatch>& batches, const TextureOptions& texture_options)
    : gl_(&gl) {
  program_ = MakeProgram(gl, "textured scene", kVertexShader, kFragmentShader);
  mvp_location_ = Uniform(gl, program_.get(), "mvp");
  for (const cv::Mat& image : textures) textures_.push_back(MakeTexture(gl, image, texture_options));

  std::vector<SceneVertex> all;
  for (const TriangleBatch& batch : batches) {
    if (batch.texture < 0 || batch.texture >= static_cast<int>(textures_.size())) {
      throw RenderError("triangle batch names texture " + std::to_string(batch.texture) + " of " +
                        std::to_string(textures_.size()));
    }
    ranges_.push_back({batch.texture, static_cast<GLint>(all.size()), static_cast<GLsizei>(batch.vertices.size())});
    all.insert(all.end(), batch.vertices.begin(), batch.vertices.end());
  }
  vao_ = MakeVertexArray(gl);
  gl.BindVertexArray(vao_.get());
  vbo_ = MakeBuffer(gl, GL_ARRAY_BUFFER, all.data(), all.size() * sizeof(SceneVertex));
  const auto stride = static_cast<GLsizei>(sizeof(SceneVertex));
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(SceneVertex, position)));
  gl.EnableVertexAttribArray(1);
  gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(SceneVertex, uv)));
  gl.EnableVertexAttribArray(2);
  gl.VertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(SceneVertex, color)));
  gl.BindVertexArray(0);
  CheckGl(gl, "textured scene upload");
}

void TexturedScene::Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view) const {
  const GlApi& gl = *gl_;
  const Eigen::Matrix4f mvp = (projection * view).cast<float>();
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  gl.Disable(GL_CULL_FACE);
  gl.UseProgram(program_.get());
  gl.UniformMatrix4fv(mvp_location_, 1, GL_FALSE, mvp.data());  // Eigen is column-major, as GL
  gl.ActiveTexture(GL_TEXTURE0);
  gl.Uniform1i(Uniform(gl, program_.get(), "albedo"), 0);
  gl.BindVertexArray(vao_.get());
  for (const Range& range : ranges_) {
    gl.BindTexture(GL_TEXTURE_2D, textures_[range.texture].get());
    gl.DrawArrays(GL_TRIANGLES, range.first, range.count);
  }
  gl.BindVertexArray(0);
}

}  // namespace arview::render
