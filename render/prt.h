#pragma once
// Per-vertex precomputed radiance transfer for a skinned character (the seed paper's dynamic
// PRT, §6.1, docs/method.md §4): for every vertex, the 9 SH coefficients of V(l)·max(n·l, 0), the
// cosine lobe times visibility, ray cast once in the bind pose. At run time the vertex shader
// rotates each vertex's transfer by its skinning rotation (band 1 as a vector, band 2 as a
// symmetric matrix, room/sh.h), so the precomputed self-shadowing follows the limbs, and
// dots it with the room's light.
//
// The character's meshes are its segments; rays are cast against all of them together (the
// paper's proxy mesh M′ of its "diffuse shadowed merged" transfer), with its relaxations for a
// multi-part mesh: a hit closer than `min_hit_fraction` of the character's size is ignored
// (the paper's ε between adjacent segments' boundaries), and the triangles that contain the
// ray's origin vertex, or any vertex at the same position in another segment (seams), are
// left out. (The paper's receiver/occluder tags come from artists; glTF has none.)
//
// Variance: the unshadowed lobe's coefficients are exact (Â_l Y_lm(n)), and only the
// occluded directions are subtracted by quadrature, so an unoccluded vertex gets exactly the
// unshadowed transfer.

#include <array>
#include <vector>

#include "anim/character.h"
#include "room/sh.h"

namespace arview::render {

using Sh9f = std::array<float, 9>;

struct PrtOptions {
  int directions = 256;            // Fibonacci sphere; about half face any vertex
  double min_hit_fraction = 2e-3;  // of the bind pose's bounding-box diagonal
  bool skip_adjacent = true;
  int threads = 2;
};

struct CharacterTransfer {
  std::vector<std::vector<Sh9f>> meshes;  // per mesh, per vertex (model space, bind pose)
  double seconds = 0;
  long long rays = 0;
  double occluded_share = 0;  // of the rays cast over the upper hemispheres
};

// Â_l Y_lm(n): the cosine lobe about n (no visibility).
room::Sh9 UnshadowedTransfer(const Eigen::Vector3d& unit_normal);

CharacterTransfer ComputeShadowedTransfer(const anim::Character& character, const PrtOptions& options = {});

}  // namespace arview::render
