#include "render/cpu_morphs.h"

#include <algorithm>

namespace arview::render {

CpuMorphs::CpuMorphs(const anim::Mesh& mesh, int target_count)
    : rest_(mesh.positions.size() * kFloatsPerVertex),
      morphed_(rest_.size()),
      morph_of_target_(static_cast<std::size_t>(std::max(target_count, 0)), -1),
      morphs_(mesh.morphs) {
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    std::copy_n(mesh.positions[v].data(), 3, &rest_[v * kFloatsPerVertex]);
    std::copy_n(mesh.normals[v].data(), 3, &rest_[v * kFloatsPerVertex + 3]);
  }
  for (std::size_t i = 0; i < morphs_.size(); ++i) {
    const int target = morphs_[i].target;
    if (target >= 0 && target < target_count) morph_of_target_[target] = static_cast<int>(i);
  }
}

std::size_t CpuMorphs::DeltaCount(std::span<const int> targets) const {
  std::size_t count = 0;
  for (const int target : targets) {
    if (target < 0 || target >= static_cast<int>(morph_of_target_.size())) continue;
    const int m = morph_of_target_[target];
    if (m >= 0) count += morphs_[m].vertices.size();
  }
  return count;
}

std::span<const float> CpuMorphs::Apply(std::span<const int> targets, std::span<const float> weights) {
  std::copy(rest_.begin(), rest_.end(), morphed_.begin());
  for (std::size_t i = 0; i < targets.size() && i < weights.size(); ++i) {
    const int target = targets[i];
    if (target < 0 || target >= static_cast<int>(morph_of_target_.size()) || morph_of_target_[target] < 0) continue;
    const anim::MeshMorph& morph = morphs_[morph_of_target_[target]];
    const float w = weights[i];
    for (std::size_t k = 0; k < morph.vertices.size(); ++k) {
      float* out = &morphed_[morph.vertices[k] * kFloatsPerVertex];
      for (int c = 0; c < 3; ++c) {
        out[c] += w * morph.position_deltas[k][c];
        out[3 + c] += w * morph.normal_deltas[k][c];
      }
    }
  }
  return morphed_;
}

}  // namespace arview::render
