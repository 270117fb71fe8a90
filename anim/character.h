#pragma once
// A skinned, animated character (loaded from a file by anim_authoring/import.h: glTF 2.0
// .glb/.gltf, FBX, Collada .dae, DirectX .X, BVH), in the asset's own units and axes ("model
// space"). These are the runtime's data; nothing here reads files.
//
//   Character c = LoadCharacter("Fox.glb");          // anim_authoring/import.h
//   c.skeleton.parents[j]      parent joint (−1 for a root); parents come before children
//   c.skeleton.inverse_bind[j] model space → joint j's space at bind time
//   c.meshes[i].positions / normals / uvs / indices (triangles) / joints / weights (≤ 4, sum 1)
//   c.materials[c.meshes[i].material].base_color and .texture (index into c.textures, or −1)
//   c.textures[k]: .path (a file), or .encoded bytes (png/jpg, decode them), or raw .rgba
//   c.clips[n].name, .duration (seconds)
//   c.skeleton.morph_targets[k]: a morph target's name; c.meshes[i].morphs: its deltas on mesh i;
//   c.clips[n].weight_tracks: its weight over time (anim/morph.h builds and checks them)
//
// Skinning (see pose.h for the jobs that compute it every frame):
//   skin_j = model_j · inverse_bind_j, where model_j is joint j's model-space transform;
//   v_model = Σ_i weights[i] · skin_{joints[i]} · v_mesh.
// Mesh positions are in model space: when every bone of a mesh agrees on where the file's rest
// pose puts it (its rest pose is its bind pose, as in Fox, CesiumMan, BCN_Epileptic and the
// FBX sample the tests load), the importer bakes that placement into the vertices (and out of
// the inverse bind matrices), so that skinning the rest pose returns the positions unchanged.
// Meshes without bones are bound rigidly (weight 1) to their nearest joint ancestor, with their
// node transform baked in so that the rest pose places them where the file does.
// BVH files carry no skin: their Character has a skeleton and clips and no meshes.

#include "anim/dual_quat.h"
#include "base/error.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace arview::anim {

// Every failure in anim/ (bad file, bad scene, bad argument) throws this, with a message that
// names the file and the problem.
struct Error : arview::Error {
  using arview::Error::Error;
};

// Local transform of a joint relative to its parent: M = T · R · S (glTF order).
struct Transform {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();

  Eigen::Matrix4d ToMatrix() const;
  DualQuatd Rigid() const { return DualQuatd::FromRotationTranslation(rotation, translation); }
  // Decomposes an affine matrix (positive scale assumed; a reflection goes into scale.z).
  static Transform FromMatrix(const Eigen::Matrix4d& m);
};

struct Skeleton {
  std::vector<std::string> names;
  std::vector<int> parents;                    // parents[j] < j; −1 for roots
  std::vector<Transform> rest;                 // local rest pose
  std::vector<Eigen::Matrix4d> inverse_bind;   // model space → joint space, at bind
  // Fixed transform of the node above the skeleton's roots, in model space (often identity);
  // model_root = root_parent · local_root.
  Eigen::Matrix4d root_parent = Eigen::Matrix4d::Identity();

  // The morph targets (blend shapes) the clips and the face key, by name; a pose carries one
  // weight per target (LocalPose::morph), as a skeleton names its joints. The deltas are the
  // meshes' (Mesh::morphs). Empty for a character without targets.
  std::vector<std::string> morph_targets;

  int size() const { return static_cast<int>(names.size()); }
  int morph_target_count() const { return static_cast<int>(morph_targets.size()); }
  // −1 when absent. Exact name match.
  int Find(const std::string& name) const;
  int FindMorphTarget(const std::string& name) const;
};

template <class V>
struct Key {
  double time = 0;  // seconds
  V value;
};

// One joint's animation. An empty list means "the rest value" for that component.
struct JointTrack {
  std::vector<Key<Eigen::Vector3d>> translation;
  std::vector<Key<Eigen::Quaterniond>> rotation;
  std::vector<Key<Eigen::Vector3d>> scale;
};

// One morph target's weight over time, interpolated linearly between keys (as glTF's LINEAR
// weights). A target without a track weighs 0 while the clip plays.
struct WeightTrack {
  int target = 0;  // index into Skeleton::morph_targets
  std::vector<Key<double>> weights;  // times increasing
};

struct Clip {
  std::string name;
  double duration = 0;           // seconds
  double ticks_per_second = 0;   // from the file (e.g. 120 for CMU BVH); 0 if it gave none
  std::vector<JointTrack> tracks;  // one per skeleton joint
  std::vector<WeightTrack> weight_tracks;  // at most one per morph target; empty: no face keys
};

struct Texture {
  std::string path;                 // an image file (absolute), or empty
  std::vector<std::uint8_t> encoded;  // or the bytes of a compressed image (png, jpg, ...)
  std::string format_hint;          // "png", "jpg", ... for `encoded`
  int width = 0, height = 0;        // or raw pixels:
  std::vector<std::uint8_t> rgba;   // width·height·4 bytes, row-major, top row first
};

struct Material {
  std::string name;
  Eigen::Vector4f base_color = Eigen::Vector4f::Ones();  // linear RGBA factor
  int texture = -1;  // base-colour texture: index into Character::textures, −1 if none
};

// One morph target's deltas on one mesh, sparse: only the vertices it moves. A weighted target
// moves vertex v to positions[v] + w·position_deltas[i] (normals likewise) before skinning.
struct MeshMorph {
  int target = 0;                                // index into Skeleton::morph_targets
  std::vector<std::uint32_t> vertices;           // increasing, below the mesh's vertex count
  std::vector<Eigen::Vector3f> position_deltas;  // one per listed vertex, model units
  std::vector<Eigen::Vector3f> normal_deltas;    // one per listed vertex (zero where none given)
};

struct Mesh {
  std::string name;
  std::vector<Eigen::Vector3f> positions;  // model space, rest pose
  std::vector<Eigen::Vector3f> normals;    // unit, same count
  std::vector<Eigen::Vector2f> uvs;        // empty when the mesh has none
  std::vector<std::uint32_t> indices;      // triangles, counter-clockwise front faces
  std::vector<std::array<std::uint16_t, 4>> joints;  // skeleton joint indices per vertex
  std::vector<Eigen::Vector4f> weights;    // matching weights, sum 1 (unused slots 0)
  int material = -1;                       // index into Character::materials
  std::vector<MeshMorph> morphs;           // at most one per morph target
  int vertex_count() const { return static_cast<int>(positions.size()); }
};

struct Character {
  std::string source;  // the file it came from
  Skeleton skeleton;
  std::vector<Clip> clips;
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;

  // nullptr when absent.
  const Clip* FindClip(const std::string& name) const;
};

}  // namespace arview::anim
