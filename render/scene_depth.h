#pragma once
// Two things the room adds to the character layer (issue 14, items 3 and 4):
//  - The cast shadow: the character's soft shadow on its floor plane from the room's dominant
//    light. The character's soft coverage seen along the light (orthographic, around its
//    bounding sphere; render/shadow_capsules.h: the posed capsules, evaluated on the CPU) is
//    mapped onto the floor and darkens the camera image directly (DarkenCastShadow), where no
//    occluder stands between the camera and the floor, before the character layer goes over it.
//  - DepthProxy: the scene proxy's triangles (room/scene_proxy.h) drawn into the depth buffer
//    only, before the character, so real things in front of the character hide it.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"
#include "render/gl_objects.h"

namespace arview::render {

// The orthographic view along a light: map → light clip space, covering a sphere. Its clip x
// axis is the floor normal's direction across the light (the way a standing character's shadow
// stretches), so that a box in clip x, y bounds a shadow tightly on the floor.
struct LightView {
  Eigen::Matrix4d map_to_clip = Eigen::Matrix4d::Identity();
  // The floor point seen at light clip (x, y): floor_origin + x · floor_x + y · floor_y.
  Eigen::Vector3d floor_origin = Eigen::Vector3d::Zero(), floor_x = Eigen::Vector3d::Zero(),
                  floor_y = Eigen::Vector3d::Zero();
  Eigen::Vector3d floor_normal = Eigen::Vector3d::UnitZ();  // unit, the light's side
  // The floor's corners under the view (map frame): the shadow can only fall inside them.
  // MakeLightView puts the whole view's there; BoundFloor narrows them.
  std::array<Eigen::Vector3d, 4> floor_corners;
  // Narrows floor_corners to the clip box [x0, x1] x [y0, y1].
  void BoundFloor(double x0, double x1, double y0, double y1);
};
// `towards_light` unit; the floor plane through `floor_point` with unit normal `floor_normal`.
// Returns false when the light is within `min_elevation_deg` of the floor's horizon (the shadow
// would stretch without bound) or below it.
bool MakeLightView(const Eigen::Vector3d& towards_light, const Eigen::Vector3d& centre, double radius,
                   const Eigen::Vector3d& floor_point, const Eigen::Vector3d& floor_normal, double min_elevation_deg,
                   LightView* view);

// The cast shadow's coverage texels a side: the light view spans the character's bounding
// sphere, so a texel is 1/32 of its radius, finer than the soft edge (0.03 of its diameter).
constexpr int kCastShadowTexels = 64;

// Darkens the camera image `frame` (BGR, seen by the pinhole camera `pinhole` from `pose`) by the
// cast shadow on the floor under `light`: alpha = strength × coverage at the floor point
// (bilinear; `coverage` from CapsuleCoverage in light.map_to_clip, kCastShadowTexels a side), and
// out = frame · (1 − alpha), as the 8-bit premultiplied layer's blend did. Only inside the
// floor quad (light.floor_corners), and not where one of `occluders` (map frame, 3 corners a
// triangle) lies between the camera and the floor (antialiased edges). Nothing when the camera
// is below the floor. Why on the CPU: drawn into the character layer, the floor quad widened
// the rectangle that is cleared, resolved and read back at 4 samples a pixel, and the occluders
// drawn into it (docs/render.md); a homography warp of a 64 x 64 image and a few polygon fills
// cost less than those passes.
void DarkenCastShadow(cv::Mat& frame, const calib::Camera& pinhole, const calib::Pose& pose, double near_m,
                      const LightView& light, const cv::Mat& coverage, float strength,
                      std::span<const Eigen::Vector3f> occluders);

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
