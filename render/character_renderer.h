#pragma once
// Draws an anim::Character skinned in the vertex shader, with dual quaternions (Kavan et al.
// 2007; the default) or linear blend skinning, base-colour textures and factors, normals, and a
// key + ambient light; and the soft contact shadow that keeps it on its ground plane.
// Morph targets (anim/morph.h) are added in the vertex shader before skinning: each mesh's deltas
// live in a buffer texture, and a draw passes the targets with a non-zero weight (at most
// kMaxActiveMorphTargets a mesh) as uniforms; a mesh with none weighted uses the program without
// morphing (docs/render.md, "Morph targets"). A mesh whose weighted targets move few vertices
// together (at most cpu_morph_max_deltas()) is morphed on the CPU instead (render/cpu_morphs.h)
// and drawn with the program without morphing.

#include <Eigen/Core>

#include <array>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "anim/character.h"
#include "anim/pose.h"
#include "render/cpu_morphs.h"
#include "render/gl_objects.h"
#include "render/prt.h"
#include "room/sh.h"

namespace arview::render {

// How the character is shaded: the old fixed key + ambient light; the room's SH light as
// diffuse irradiance at each pixel's normal (unshadowed); or the room's SH light through the
// per-vertex PRT transfer (self-shadowed, rotated with the skinning).
enum class LightingMode { kFixed, kShUnshadowed, kShShadowed };
// "fixed" | "sh" | "prt"; throws RenderError otherwise.
LightingMode ParseLightingMode(const std::string& name);
std::string LightingModeName(LightingMode mode);

struct CharacterDraw {
  Eigen::Matrix4d model_to_map = Eigen::Matrix4d::Identity();
  std::span<const Eigen::Matrix4f> skinning_matrices;     // for kLinear (and the DQ fallback)
  std::span<const anim::DualQuatf> skinning_dual_quats;   // for kDualQuaternion
  anim::SkinningMethod method = anim::SkinningMethod::kDualQuaternion;
  Eigen::Vector3d light_direction_map = Eigen::Vector3d::UnitZ();  // unit, towards the light
  float key = 0.7f;
  float ambient = 0.45f;
  // Skip triangles facing away (counter-clockwise front faces, as anim/ imports them): half the
  // rasterisation for closed meshes; off for assets with open, single-sided parts.
  bool cull_back_faces = true;
  LightingMode lighting = LightingMode::kFixed;
  room::ShRgb sh{};  // the room's incident radiance (map frame, RGB) for the SH modes
  // One weight per morph target of the character (AnimatorFrame::morph_weights), or empty: none.
  std::span<const float> morph_weights;
};

class CharacterRenderer {
 public:
  // The most targets one mesh applies in a draw: the largest weights (by magnitude) are applied,
  // the others dropped and counted (morph_targets_dropped()).
  static constexpr int kMaxActiveMorphTargets = 32;

  // Uploads meshes and textures; throws RenderError when the character has more joints than
  // the vertex shader can take, or a texture cannot be decoded.
  CharacterRenderer(const GlApi& gl, const anim::Character& character);
  // Draws into the bound framebuffer with depth testing. Dual-quaternion skinning needs rigid
  // skinning transforms; with scaled joints it falls back to linear blend (see used_linear()).
  void Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, const CharacterDraw& draw);
  bool used_linear_fallback() const { return used_linear_fallback_; }
  int joint_count() const { return joints_; }
  int triangle_count() const { return triangles_; }
  // Per joint, the farthest any vertex it influences lies from it at bind time (model units):
  // every skinned vertex stays within these spheres around the posed joints (for rigid joints),
  // which bounds the character on screen.
  const std::vector<float>& joint_radii() const { return joint_radii_; }
  // The same with a frame's morph targets: each radius grows by Σ_k |w_k| · (the farthest target
  // k moves a vertex the joint influences). Valid until the next call; no allocation.
  std::span<const float> JointRadii(std::span<const float> morph_weights);
  // Uploads per-vertex PRT transfer (ComputeShadowedTransfer of the same character); needed by
  // LightingMode::kShShadowed. Throws RenderError when the vertex counts differ.
  void SetTransfer(const CharacterTransfer& transfer);
  bool has_transfer() const { return has_transfer_; }
  int morph_target_count() const { return morph_targets_; }
  // Of the last draw, summed over the meshes: the targets applied, and those dropped beyond
  // kMaxActiveMorphTargets.
  int morph_targets_applied() const { return morph_applied_; }
  int morph_targets_dropped() const { return morph_dropped_; }
  // Of the last draw: the meshes morphed on the CPU (the others with weighted targets used the
  // morph program).
  int morphed_meshes_on_cpu() const { return morphed_on_cpu_; }
  // A mesh's weighted targets are added on the CPU when they hold at most this many vertex deltas
  // together, else in the vertex shader. 0: always the shader. The default: a face's few targets
  // (the built-in figure's mouth, lids and brows move 50-900 vertices each) take microseconds on
  // the CPU, while a head whose 52 targets each move all its vertices stays in the shader.
  static constexpr int kDefaultCpuMorphMaxDeltas = 16384;
  void set_cpu_morph_max_deltas(int deltas) { cpu_morph_max_deltas_ = deltas; }
  int cpu_morph_max_deltas() const { return cpu_morph_max_deltas_; }

 private:
  struct GpuMesh {
    GlName vao, vbo, ibo, transfer_vbo;
    GLsizei index_count = 0;
    int vertex_count = 0;
    Eigen::Vector4f base_color = Eigen::Vector4f::Ones();
    int texture = -1;  // index into textures_, −1: none (the untextured program)
    // Morph deltas: per target that moves this mesh, vertex_count position texels then
    // vertex_count normal texels (RGB32F) in one buffer texture; morph_base[target] is the
    // first texel of a target's, −1 where it does not move this mesh.
    GlName morph_buffer, morph_texture;
    std::vector<int> morph_base;
    // The CPU path: the mesh's rest pose and deltas, and a vertex array whose positions and
    // normals come from morphed_vbo (rewritten each draw that uses it), the rest from vbo.
    std::unique_ptr<CpuMorphs> cpu_morphs;
    GlName morphed_vao, morphed_vbo;
  };
  // This draw's targets for one mesh, in active_base_/active_weight_; returns their count.
  int ActiveMorphs(const GpuMesh& mesh, std::span<const float> weights);
  void UploadMorphs(const anim::Mesh& mesh, const std::string& source, GpuMesh& gpu);
  void MakeCpuMorphPath(const anim::Mesh& mesh, GpuMesh& gpu);
  // Whether this draw's `count` active targets of `mesh` go through the CPU; if so, uploads the
  // morphed vertices.
  bool MorphOnCpu(GpuMesh& mesh, int count);
  void AddMorphReach(const anim::Mesh& mesh, const std::vector<Eigen::Matrix4f>& inverse_bind);
  const GlApi* gl_;
  int joints_ = 0;
  int triangles_ = 0;
  struct Locations {
    GLint mvp, model, normal_matrix, skin, dq_real, dq_dual, light, key, ambient, base_color, albedo;
    GLint model_rotation, sh;
    GLint morph_deltas, morph_count, morph_base, morph_weight, morph_vertices;
  };
  struct Program {
    GlName program;
    Locations loc{};
  };
  // One program per variant (skinning method x lighting mode x textured or not x morphed or
  // not), compiled on first use: llvmpipe pays for every branch of a shader that branches on
  // uniforms.
  const Program& ProgramFor(bool dual_quaternion, LightingMode lighting, bool textured, bool morphed = false);
  // What a draw sets in each program it uses (all but the mesh's colour), computed once a draw.
  struct DrawUniforms {
    bool dual = true;
    LightingMode lighting = LightingMode::kFixed;
    Eigen::Matrix4f mvp, model;
    Eigen::Matrix3f normal_matrix, model_rotation;
    Eigen::Vector3f light;
    float sh[27] = {};
  };
  // Binds `program` and sets the draw's uniforms in it; returns it.
  const Program& UseProgram(const Program& program, const DrawUniforms& u, const CharacterDraw& d);
  std::array<std::unique_ptr<Program>, 24> programs_;
  std::vector<GlName> textures_;
  std::vector<GpuMesh> meshes_;
  bool used_linear_fallback_ = false;
  bool has_transfer_ = false;
  std::vector<float> joint_radii_;
  std::vector<float> dq_upload_;
  int morph_targets_ = 0;
  std::vector<float> morph_reach_;  // [target · joints + joint]: the farthest the target moves a vertex of the joint
  std::vector<float> frame_radii_;  // JointRadii's
  int morph_applied_ = 0, morph_dropped_ = 0;
  std::vector<std::pair<float, int>> morph_candidates_;  // (|weight|, target); reserved at upload
  std::array<GLint, kMaxActiveMorphTargets> active_base_{};
  std::array<GLfloat, kMaxActiveMorphTargets> active_weight_{};
  std::array<int, kMaxActiveMorphTargets> active_target_{};
  int cpu_morph_max_deltas_ = kDefaultCpuMorphMaxDeltas;
  int morphed_on_cpu_ = 0;
};

// A soft elliptical shadow on a ground plane, drawn before the character into the transparent
// character layer as premultiplied black with alpha, so it darkens the video it is blended over.
class ContactShadow {
 public:
  explicit ContactShadow(const GlApi& gl);
  // `center` on the plane; `axis_u`, `axis_v` in the plane with lengths = the ellipse's radii;
  // `strength` in [0, 1] is the darkening at the centre.
  void Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, const Eigen::Vector3d& center,
            const Eigen::Vector3d& axis_u, const Eigen::Vector3d& axis_v, float strength);

 private:
  const GlApi* gl_;
  GlName program_, vao_, vbo_;
  GLint mvp_ = -1, strength_ = -1;
};

}  // namespace arview::render
