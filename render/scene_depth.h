#pragma once
// Two things the room adds to the character layer (issue 14, items 3 and 4):
//  - CastShadow: the character's soft shadow on its floor plane from the room's dominant light.
//    The skinned character is drawn as a white silhouette into a 128 x 128 texture, seen along
//    the light (orthographic, around the character's bounding sphere); the floor's
//    parallelogram under that view is then drawn into the layer, each pixel darkened by the
//    silhouette coverage at its point projected along the light, averaged over 4 taps from a
//    blurred mip level (a soft, percentage-closer-style edge), computed once per silhouette at
//    half its resolution (the taps read level 1.5) and sampled bilinearly by the floor.
//  - DepthProxy: the scene proxy's triangles (render/scene_proxy.h) drawn into the depth buffer
//    only, before the character, so real things in front of the character hide it.

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "render/gl_objects.h"

namespace arview::render {

// The orthographic view along a light: map → light clip space, covering a sphere.
struct LightView {
  Eigen::Matrix4d map_to_clip = Eigen::Matrix4d::Identity();
  // The floor's corners under the view (map frame): the shadow can only fall inside them.
  std::array<Eigen::Vector3d, 4> floor_corners;
};
// `towards_light` unit; the floor plane through `floor_point` with unit normal `floor_normal`.
// Returns false when the light is within `min_elevation_deg` of the floor's horizon (the shadow
// would stretch without bound) or below it.
bool MakeLightView(const Eigen::Vector3d& towards_light, const Eigen::Vector3d& centre, double radius,
                   const Eigen::Vector3d& floor_point, const Eigen::Vector3d& floor_normal, double min_elevation_deg,
                   LightView* view);

class CastShadow {
 public:
  explicit CastShadow(const GlApi& gl, int size = 128);
  // Binds the silhouette target (cleared, viewport set): draw the character with
  // LightView::map_to_clip as projection, an identity view, and CharacterDraw::silhouette.
  void BeginSilhouette();
  // Mipmaps the silhouette and blurs it into the soft coverage the receiver samples;
  // `softness`: the blur radius as a share of the light view's width. The caller then binds its
  // own framebuffer again.
  void EndSilhouette(float softness);
  // Into the bound framebuffer, premultiplied black: alpha = strength × soft coverage (pixels
  // with no shadow are left alone).
  void DrawReceiver(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, const LightView& light,
                    float strength);

 private:
  // The soft coverage's texels a side: half the silhouette's (it is read from level 1.5).
  int BlurredSize() const { return std::max(1, size_ / 2); }
  const GlApi* gl_;
  int size_;
  GlName texture_, fbo_, blurred_, blurred_fbo_, program_, blur_program_, vao_;
  GLint mvp_ = -1, light_ = -1, corners_ = -1, strength_ = -1, blurred_sampler_ = -1;
  GLint softness_ = -1, blur_size_ = -1, silhouette_ = -1;
};

class DepthProxy {
 public:
  DepthProxy(const GlApi& gl, const std::vector<Eigen::Vector3f>& triangles);
  int triangle_count() const { return count_ / 3; }
  // Depth only (colour writes off), depth test on. Only the triangles with a corner nearer to
  // the camera than `farthest` (distance along the view axis, map units) are drawn: one
  // wholly behind everything drawn after it can hide nothing, and the walls behind a character
  // cover its whole rectangle at every sample (the pass's main cost, measured in
  // docs/render.md). Infinity draws them all.
  void Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view,
            double farthest = std::numeric_limits<double>::infinity());
  // Triangles the last Draw drew.
  int drawn_triangles() const { return drawn_ / 3; }

 private:
  const GlApi* gl_;
  std::vector<Eigen::Vector3f> triangles_;
  std::vector<std::uint32_t> indices_;  // this frame's triangles
  GlName program_, vao_, vbo_, ibo_;
  GLsizei count_ = 0, drawn_ = 0;
  GLint mvp_ = -1;
};

}  // namespace arview::render
