#include "anim/morph.h"

#include <algorithm>
#include <cmath>

namespace arview::anim {
namespace {

bool Finite(const Eigen::Vector3f& v) { return v.allFinite(); }

std::string TargetLabel(const Character& c, int target) {
  const std::string name = target >= 0 && target < c.skeleton.morph_target_count() ? c.skeleton.morph_targets[target]
                                                                                     : "#" + std::to_string(target);
  return c.source + ": morph target '" + name + "'";
}

void CheckMeshMorph(const Character& c, const Mesh& mesh, const MeshMorph& m) {
  const std::string where = TargetLabel(c, m.target);
  if (m.target < 0 || m.target >= c.skeleton.morph_target_count())
    throw Error(where + ": mesh '" + mesh.name + "' has deltas for a target the character does not have (" +
                std::to_string(c.skeleton.morph_target_count()) + " targets)");
  if (m.position_deltas.size() != m.vertices.size() || m.normal_deltas.size() != m.vertices.size())
    throw Error(where + ": mesh '" + mesh.name + "' lists " + std::to_string(m.vertices.size()) + " vertices with " +
                std::to_string(m.position_deltas.size()) + " position and " + std::to_string(m.normal_deltas.size()) +
                " normal deltas");
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    if (m.vertices[i] >= static_cast<std::uint32_t>(mesh.vertex_count()) || (i > 0 && m.vertices[i] <= m.vertices[i - 1]))
      throw Error(where + ": mesh '" + mesh.name + "' has vertex " + std::to_string(m.vertices[i]) +
                  " out of range or out of order (" + std::to_string(mesh.vertex_count()) + " vertices)");
    if (!Finite(m.position_deltas[i]) || !Finite(m.normal_deltas[i]))
      throw Error(where + ": a non-finite delta at vertex " + std::to_string(m.vertices[i]) + " of mesh '" + mesh.name + "'");
  }
}

void CheckWeightTrack(const Character& c, const Clip& clip, const WeightTrack& track) {
  const std::string where = TargetLabel(c, track.target);
  if (track.target < 0 || track.target >= c.skeleton.morph_target_count())
    throw Error(where + ": clip '" + clip.name + "' has a weight track for a target the character does not have (" +
                std::to_string(c.skeleton.morph_target_count()) + " targets)");
  for (std::size_t k = 0; k < track.weights.size(); ++k) {
    const Key<double>& key = track.weights[k];
    if (!std::isfinite(key.time) || !std::isfinite(key.value) || (k > 0 && key.time < track.weights[k - 1].time))
      throw Error(where + ": clip '" + clip.name + "' has a non-finite or out-of-order weight key (" +
                  std::to_string(k) + ")");
  }
}

// Checks each item (a mesh's deltas, a clip's weight tracks), then that no target has two.
template <class Item, class CheckItem>
void CheckOncePerTarget(const Character& c, const std::vector<Item>& items, const std::string& twice, CheckItem check) {
  std::vector<bool> seen(c.skeleton.morph_targets.size(), false);
  for (const Item& item : items) {
    check(item);
    if (seen[item.target]) throw Error(TargetLabel(c, item.target) + ": " + twice);
    seen[item.target] = true;
  }
}

}  // namespace

int AddMorphTarget(Character& c, const std::string& name, int mesh, std::span<const Eigen::Vector3f> position_deltas,
                   std::span<const Eigen::Vector3f> normal_deltas) {
  const std::string where = c.source + ": morph target '" + name + "'";
  if (name.empty()) throw Error(c.source + ": a morph target needs a name");
  if (mesh < 0 || mesh >= static_cast<int>(c.meshes.size()))
    throw Error(where + ": mesh " + std::to_string(mesh) + " out of range (" + std::to_string(c.meshes.size()) + " meshes)");
  Mesh& m = c.meshes[mesh];
  const std::size_t n = m.positions.size();
  if (position_deltas.size() != n || (!normal_deltas.empty() && normal_deltas.size() != n))
    throw Error(where + ": " + std::to_string(position_deltas.size()) + " position and " +
                std::to_string(normal_deltas.size()) + " normal deltas for mesh '" + m.name + "' of " + std::to_string(n) +
                " vertices");
  int target = c.skeleton.FindMorphTarget(name);
  if (target >= 0) {
    for (const MeshMorph& existing : m.morphs)
      if (existing.target == target) throw Error(where + ": mesh '" + m.name + "' already has its deltas");
  }
  MeshMorph morph;
  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Vector3f dn = normal_deltas.empty() ? Eigen::Vector3f::Zero() : normal_deltas[v];
    if (!Finite(position_deltas[v]) || !Finite(dn))
      throw Error(where + ": a non-finite delta at vertex " + std::to_string(v) + " of mesh '" + m.name + "'");
    if (position_deltas[v].isZero(0) && dn.isZero(0)) continue;
    morph.vertices.push_back(static_cast<std::uint32_t>(v));
    morph.position_deltas.push_back(position_deltas[v]);
    morph.normal_deltas.push_back(dn);
  }
  if (target < 0) {
    target = c.skeleton.morph_target_count();
    c.skeleton.morph_targets.push_back(name);
  }
  morph.target = target;
  m.morphs.push_back(std::move(morph));
  return target;
}

void CheckMorphTargets(const Character& c) {
  const std::vector<std::string>& names = c.skeleton.morph_targets;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k].empty()) throw Error(c.source + ": morph target " + std::to_string(k) + " has no name");
    if (std::find(names.begin(), names.begin() + k, names[k]) != names.begin() + k)
      throw Error(TargetLabel(c, static_cast<int>(k)) + ": two targets have this name");
  }
  for (const Mesh& mesh : c.meshes)
    CheckOncePerTarget(c, mesh.morphs, "mesh '" + mesh.name + "' has its deltas twice",
                       [&](const MeshMorph& m) { CheckMeshMorph(c, mesh, m); });
  for (const Clip& clip : c.clips)
    CheckOncePerTarget(c, clip.weight_tracks, "clip '" + clip.name + "' keys it twice",
                       [&](const WeightTrack& t) { CheckWeightTrack(c, clip, t); });
}

void ApplyMorphTargets(const Mesh& mesh, std::span<const float> weights, std::vector<Eigen::Vector3f>& positions,
                       std::vector<Eigen::Vector3f>& normals) {
  positions = mesh.positions;
  normals = mesh.normals;
  for (const MeshMorph& m : mesh.morphs) {
    const float w = m.target < static_cast<int>(weights.size()) ? weights[m.target] : 0.f;
    if (w == 0.f) continue;
    for (std::size_t i = 0; i < m.vertices.size(); ++i) {
      positions[m.vertices[i]] += w * m.position_deltas[i];
      normals[m.vertices[i]] += w * m.normal_deltas[i];
    }
  }
}

bool WeightTracksFit(std::span<const WeightTrack> tracks, int target_count, std::size_t pose_weights) {
  if (pose_weights != 0 && pose_weights != static_cast<std::size_t>(target_count)) return false;
  return std::all_of(tracks.begin(), tracks.end(),
                     [&](const WeightTrack& t) { return t.target >= 0 && t.target < target_count; });
}

void SampleWeightTracks(std::span<const WeightTrack> tracks, double t, LocalPose& out) {
  out.morph_keyed = false;
  if (out.morph.empty() || tracks.empty()) return;
  std::fill(out.morph.begin(), out.morph.end(), 0.f);
  for (const WeightTrack& track : tracks) {
    const std::vector<Key<double>>& keys = track.weights;
    if (keys.empty()) continue;
    double w = keys.back().value;
    if (t <= keys.front().time) {
      w = keys.front().value;
    } else if (t < keys.back().time) {
      const auto next = std::upper_bound(keys.begin(), keys.end(), t, [](double x, const Key<double>& k) { return x < k.time; });
      const Key<double>& a = *(next - 1);
      const double span = next->time - a.time;
      w = span > 0 ? a.value + (next->value - a.value) * (t - a.time) / span : next->value;
    }
    out.morph[track.target] = static_cast<float>(w);
  }
  out.morph_keyed = true;
}

}  // namespace arview::anim
