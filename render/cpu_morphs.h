#pragma once
// Morph targets added on the CPU for one mesh: its rest positions and normals plus the weighted
// sparse deltas of the targets a draw applies, as one interleaved stream (3 position and 3
// normal floats a vertex) that CharacterRenderer uploads and draws with its program without
// morphing. Why: the shader path fetches two texels per weighted target for every vertex of the
// mesh, where a face's targets each move a few hundred of its vertices; on Mesa's llvmpipe the
// vertex shader runs on the CPU anyway, and that per-vertex loop was most of the face's cost
// (docs/figure.md, "Cost"; docs/render.md, "Morph targets").

#include <cstddef>
#include <span>
#include <vector>

#include "anim/character.h"

namespace arview::render {

class CpuMorphs {
 public:
  // `mesh`'s rest pose and morphs; `target_count`: the character's morph targets (MeshMorph::target
  // indexes them). The caller has checked the morphs fit the mesh (CharacterRenderer's upload).
  CpuMorphs(const anim::Mesh& mesh, int target_count);

  // How many vertex deltas `targets` hold together: the work of Apply beyond copying the rest pose.
  std::size_t DeltaCount(std::span<const int> targets) const;

  // The rest pose plus Σ_i weights[i] · deltas of targets[i] (targets that do not move this mesh
  // add nothing). Valid until the next call; no allocation.
  std::span<const float> Apply(std::span<const int> targets, std::span<const float> weights);

  static constexpr int kFloatsPerVertex = 6;

 private:
  std::vector<float> rest_;     // vertex_count x kFloatsPerVertex
  std::vector<float> morphed_;  // Apply's result
  std::vector<int> morph_of_target_;  // target -> index into morphs_, -1 where it does not move the mesh
  std::vector<anim::MeshMorph> morphs_;
};

}  // namespace arview::render
