#pragma once
// Morph targets (blend shapes): the face channel of a character, beside its joints. A target has
// a name (Skeleton::morph_targets), sparse position and normal deltas on the meshes it moves
// (Mesh::morphs) and, in clips, a weight track (Clip::weight_tracks). A pose carries one weight
// per target (LocalPose::morph); the animator hands them to the renderer in AnimatorFrame, which
// adds Σ w_k·delta_k to each vertex before skinning, for the targets whose weight is not zero.
//
//   int blink = AddMorphTarget(c, "eyeBlinkLeft", head, deltas);  // a generated character (figure/)
//   CheckMorphTargets(c);                                          // after import: one clear error
//   ApplyMorphTargets(mesh, frame.morph_weights, positions, normals);  // the same sum on the CPU
//
// Sampling a clip's weight tracks is part of SamplingJob and PreparedSamplingJob; blending them is
// the frame blender's (schedule.h); neither allocates.

#include "anim/pose.h"

#include <span>
#include <string>
#include <vector>

namespace arview::anim {

// Adds the target `name` (or, when the character has one of that name, its deltas on another
// mesh) with dense per-vertex deltas on mesh `mesh`: one position delta per vertex and either no
// normal deltas or one per vertex. Only the vertices with a non-zero delta are stored. Returns the
// target's index. Throws Error naming the character and the target when the mesh index is out of
// range, a count is not the mesh's vertex count, a delta is not finite, or the mesh already has
// deltas for the target.
int AddMorphTarget(Character& character, const std::string& name, int mesh, std::span<const Eigen::Vector3f> position_deltas,
                   std::span<const Eigen::Vector3f> normal_deltas = {});

// Throws Error("<source>: morph target '<name>': <what is wrong>") when a target is unnamed or
// named twice, a mesh's deltas name a target that does not exist, list a vertex out of range or
// out of order, have counts that differ from their vertex list or non-finite values, or a clip's
// weight track keys a missing target, keys one twice, or has non-finite or unordered keys.
void CheckMorphTargets(const Character& character);

// The mesh's positions and normals with the weighted deltas added (weights: one per target of the
// character, or empty for none). Normals are not renormalised, as in the vertex shader, which
// leaves that to the fragment shader.
void ApplyMorphTargets(const Mesh& mesh, std::span<const float> weights, std::vector<Eigen::Vector3f>& positions,
                       std::vector<Eigen::Vector3f>& normals);

// Whether `tracks` key only targets below `target_count`, and a pose with `pose_weights` weights
// can take them: one per target, or none (a pose sized for joints alone samples no face).
bool WeightTracksFit(std::span<const WeightTrack> tracks, int target_count, std::size_t pose_weights);
// A clip's weights at time t (seconds, already wrapped or clamped into the clip): every target
// without a track at 0, each track interpolated linearly (held beyond its ends). A pose without
// weights, or a clip without tracks, leaves the pose's weights and marks them unkeyed.
void SampleWeightTracks(std::span<const WeightTrack> tracks, double t, LocalPose& out);

}  // namespace arview::anim
