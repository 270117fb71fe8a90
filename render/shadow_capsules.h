#pragma once
// The cast shadow's occluder (issue 14, item 3): the character as one capsule per joint,
// fitted once to the bind-pose vertices that the joint moves most, posed with the joints every
// frame; its soft coverage seen along the light is evaluated on the CPU. A capsule seen along
// any direction is a 2D stadium (the projected segment, thickened by the radius), so the
// coverage is a distance to a segment per texel, for the few texels each capsule spans.
//
// Why not the mesh: drawing the skinned character a second time from the light (every vertex
// skinned again, mipmaps, a blur pass, two framebuffer switches) was the largest part of the
// room lighting's cost for 25 000 triangles (docs/render.md). Capsule shadows are the usual
// real-time stand-in for a character's soft shadow; the price is a rounder outline (thin flat
// parts such as ears become tubes), which the blur of a soft shadow mostly hides (measured
// against the mesh's own outline in lighting_test.cpp).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <span>
#include <vector>

#include "anim/character.h"

namespace arview::render {

struct ShadowCapsule {
  int joint = 0;
  // The segment's ends in the joint's bind-pose frame (inverse_bind · position), model units.
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0;
};

// One capsule per joint that moves vertices: fitted to the vertices whose heaviest influence it
// is or that it moves with at least 35% of their weight; the axis is their principal direction,
// the radius the distance from it within which 75% of them lie, and the segment the shortest
// one on that axis whose capsule holds every vertex within that radius (a ball's cluster gets a
// point, a limb's the limb's length).
std::vector<ShadowCapsule> FitShadowCapsules(const anim::Character& character);

// The capsules posed: `joint_to_map[j]` = model_to_map · the joint's model transform; the
// radius is scaled by the transform's largest axis scale. Map frame.
std::vector<ShadowCapsule> PoseShadowCapsules(std::span<const ShadowCapsule> capsules,
                                              std::span<const Eigen::Matrix4d> joint_to_map);

// The smallest axis-aligned box's centre and the radius around it that hold every posed capsule.
void CapsuleBounds(std::span<const ShadowCapsule> posed, Eigen::Vector3d* centre, double* radius);

// Soft coverage of posed capsules in an orthographic light view (`map_to_clip`: map → light
// clip space; x and y in [−1, 1] span the texture): 8-bit, `size` x `size`, texel (column c,
// row r) at clip (−1 + (2c + 1) / size, −1 + (2r + 1) / size), so that row 0 is texture
// coordinate v = 0. Each capsule covers 1 within its radius less `softness` and 0 beyond its
// radius plus `softness` (clip units), smoothly in between; overlapping capsules take the
// largest. `support`: the texels that are not 0 (empty when none).
void CapsuleCoverage(std::span<const ShadowCapsule> posed, const Eigen::Matrix4d& map_to_clip, double softness, int size,
                     cv::Mat* coverage, cv::Rect* support);

}  // namespace arview::render
