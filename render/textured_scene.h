#pragma once
// A static scene of textured triangles (the synthetic room, test targets): every batch of
// triangles samples one texture, multiplied by a per-vertex colour. No lighting: the room's
// shading is baked into the vertex colours so that brightness is constant over time, as
// tracking features expect from a matte room under steady light.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

#include "render/gl_objects.h"

namespace arview::render {

struct SceneVertex {
  float position[3];
  float uv[2];     // texture coordinates, v = 0 at the image's top row
  float color[3];  // multiplies the texture
};

struct TriangleBatch {
  int texture = 0;  // index into the textures given to TexturedScene
  std::vector<SceneVertex> vertices;  // triangle list
};

// A planar rectangle split in two triangles. Corners in order top-left, top-right,
// bottom-right, bottom-left as seen from the side that shows the texture upright; uv_rect =
// (u0, v0, u1, v1) selects the part of the texture.
void AppendQuad(TriangleBatch& batch, const Eigen::Vector3d corners[4], const Eigen::Vector4f& uv_rect,
                const Eigen::Vector3f& color);

class TexturedScene {
 public:
  TexturedScene(const GlApi& gl, const std::vector<cv::Mat>& textures, const std::vector<TriangleBatch>& batches,
                const TextureOptions& texture_options = {});
  // Draws into the currently bound framebuffer with depth testing.
  void Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view) const;

 private:
  struct Range {
    int texture;
    GLint first;
    GLsizei count;
  };
  const GlApi* gl_;
  GlName program_, vao_, vbo_;
  std::vector<GlName> textures_;
  std::vector<Range> ranges_;
  GLint mvp_location_ = -1;
};

}  // namespace arview::render
