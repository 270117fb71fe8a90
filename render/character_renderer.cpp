#include "render/character_renderer.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>

#include "base/image_file.h"
#include "render/offscreen.h"

namespace arview::render {
namespace {

// Per-vertex data; joints as integers (glVertexAttribIPointer), weights sum to 1.
struct CharacterVertex {
  float position[3];
  float normal[3];
  float uv[2];
  std::uint16_t joints[4];
  float weights[4];
};

// Points the bound vertex array's attributes at the bound GL_ARRAY_BUFFER of CharacterVertex:
// position and normal (0, 1) when `with_position_and_normal`, always uv, joints and weights
// (2, 3, 4). The CPU morph path's vertex array takes 0 and 1 from a buffer of its own.
void PointAtCharacterVertices(const GlApi& gl, bool with_position_and_normal) {
  const auto stride = static_cast<GLsizei>(sizeof(CharacterVertex));
  const auto attribute = [&](GLuint location, GLint size, size_t offset) {
    gl.EnableVertexAttribArray(location);
    gl.VertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offset));
  };
  if (with_position_and_normal) {
    attribute(0, 3, offsetof(CharacterVertex, position));
    attribute(1, 3, offsetof(CharacterVertex, normal));
  }
  attribute(2, 2, offsetof(CharacterVertex, uv));
  gl.EnableVertexAttribArray(3);
  gl.VertexAttribIPointer(3, 4, GL_UNSIGNED_SHORT, stride, reinterpret_cast<void*>(offsetof(CharacterVertex, joints)));
  attribute(4, 4, offsetof(CharacterVertex, weights));
}

struct ProgramVariant {
  bool dual_quaternion = true;
  LightingMode lighting = LightingMode::kFixed;
  bool textured = true;  // false: the material's colour alone, no texture fetch
  bool morphed = false;  // adds the weighted morph target deltas before skinning
  size_t Index() const {  // 0..23
    return 12 * (morphed ? 1 : 0) + 4 * static_cast<size_t>(lighting) + (dual_quaternion ? 2 : 0) + (textured ? 1 : 0);
  }
};

// The program's variant, as preprocessor definitions: llvmpipe runs both sides of a branch on a
// uniform (its SIMD lanes are masked, not skipped), so one program for every mode paid for linear
// blend and dual-quaternion skinning, the PRT rotation and the SH irradiance in every pass.
std::string VariantDefines(const ProgramVariant& v) {
  return "#version 450 core\n#define DUAL_QUATERNION " + std::to_string(v.dual_quaternion ? 1 : 0) +
         "\n#define LIGHTING " + std::to_string(static_cast<int>(v.lighting)) + "\n#define TEXTURED " +
         std::to_string(v.textured ? 1 : 0) + "\n#define MORPH " + std::to_string(v.morphed ? 1 : 0) +
         "\n#define MAX_MORPHS " + std::to_string(CharacterRenderer::kMaxActiveMorphTargets) + "\n";
}

std::string VertexShader(int joints, const ProgramVariant& variant) {
  return VariantDefines(variant) + "#define JOINTS " + std::to_string(joints) + R"(
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in uvec4 joints;
layout(location = 4) in vec4 weights;
layout(location = 5) in vec3 transfer0;  // PRT: SH coefficients 0-2 (bind pose, model space)
layout(location = 6) in vec3 transfer1;  // 3-5
layout(location = 7) in vec3 transfer2;  // 6-8
uniform mat4 mvp;            // projection · view · model_to_map
uniform mat4 model;          // model_to_map
uniform mat3 normal_matrix;  // inverse transpose of model_to_map's 3x3
uniform mat4 skin[JOINTS];
uniform vec4 dq_real[JOINTS];  // quaternion (x, y, z, w)
uniform vec4 dq_dual[JOINTS];
// LIGHTING 0: fixed key + ambient, 1: SH irradiance, 2: SH with PRT transfer. DUAL_QUATERNION 0:
// linear blend skinning.
uniform mat3 model_rotation; // model_to_map's rotation, without its scale
uniform vec3 sh[9];          // incident radiance (map frame), RGB
#if MORPH
// The mesh's deltas (per target: the positions of every vertex, then the normals), and this
// draw's targets with a non-zero weight: their first texel and weight.
uniform samplerBuffer morph_deltas;
uniform int morph_count;
uniform int morph_base[MAX_MORPHS];
uniform float morph_weight[MAX_MORPHS];
uniform int morph_vertices;
#endif
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_prt;              // lighting 2: radiance / albedo at the vertex

vec3 rotate(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }

mat3 quat_matrix(vec4 q) {
  return mat3(rotate(q, vec3(1, 0, 0)), rotate(q, vec3(0, 1, 0)), rotate(q, vec3(0, 0, 1)));
}

// Dynamic PRT: the vertex's bind-pose transfer rotated by its skinning rotation r (band 1 as a
// vector, band 2 as the symmetric matrix Q of f(w) = wQw, Q' = r Q rT), dotted with the light.
vec3 prt_radiance(mat3 r) {
  const float k1 = 1.092548430592079, k0 = 0.315391565252520, k2 = 0.546274215296040;
  float t[9] = float[9](transfer0.x, transfer0.y, transfer0.z, transfer1.x, transfer1.y, transfer1.z,
                        transfer2.x, transfer2.y, transfer2.z);
  vec3 b1 = r * vec3(t[3], t[1], t[2]);
  mat3 q = mat3(-k0 * t[6] + k2 * t[8], 0.5 * k1 * t[4], 0.5 * k1 * t[7],
                0.5 * k1 * t[4], -k0 * t[6] - k2 * t[8], 0.5 * k1 * t[5],
                0.5 * k1 * t[7], 0.5 * k1 * t[5], 2.0 * k0 * t[6]);
  mat3 qr = r * q * transpose(r);
  vec3 l = sh[0] * t[0] + sh[1] * b1.y + sh[2] * b1.z + sh[3] * b1.x +
           sh[4] * (2.0 * qr[1][0] / k1) + sh[5] * (2.0 * qr[2][1] / k1) + sh[6] * (qr[2][2] / (2.0 * k0)) +
           sh[7] * (2.0 * qr[2][0] / k1) + sh[8] * ((qr[0][0] - qr[1][1]) / (2.0 * k2));
  return max(l, vec3(0.0)) / 3.14159265358979;
}

void main() {
  vec3 p;
  vec3 n;
  mat3 skin_rotation;
  // Morph targets first, in the bind pose (glTF's order: morph, then skin).
  vec3 bind_position = position;
  vec3 bind_normal = normal;
#if MORPH
  for (int i = 0; i < morph_count; ++i) {
    int texel = morph_base[i] + gl_VertexID;
    bind_position += morph_weight[i] * texelFetch(morph_deltas, texel).xyz;
    bind_normal += morph_weight[i] * texelFetch(morph_deltas, texel + morph_vertices).xyz;
  }
#endif
#if DUAL_QUATERNION
  // Kavan et al. 2007: blend in the hemisphere of the first joint, normalise, apply.
  vec4 r0 = dq_real[joints.x];
  vec4 real = vec4(0.0);
  vec4 dual = vec4(0.0);
  for (int i = 0; i < 4; ++i) {
    float w = weights[i];
    vec4 r = dq_real[joints[i]];
    if (dot(r, r0) < 0.0) w = -w;
    real += w * r;
    dual += w * dq_dual[joints[i]];
  }
  float len = length(real);
  real /= len;
  dual /= len;
  // translation = 2 · dual · conj(real)
  vec3 t = 2.0 * (real.w * dual.xyz - dual.w * real.xyz + cross(real.xyz, dual.xyz));
  p = rotate(real, bind_position) + t;
  n = rotate(real, bind_normal);
#if LIGHTING == 2
  skin_rotation = quat_matrix(real);
#endif
#else
  mat4 m = weights.x * skin[joints.x] + weights.y * skin[joints.y] + weights.z * skin[joints.z] +
           weights.w * skin[joints.w];
  p = (m * vec4(bind_position, 1.0)).xyz;
  n = mat3(m) * bind_normal;
#if LIGHTING == 2
  // The rotation of the blended matrix (Gram-Schmidt): SH rotation needs an orthogonal one.
  vec3 x = normalize(m[0].xyz);
  vec3 y = normalize(m[1].xyz - dot(m[1].xyz, x) * x);
  skin_rotation = mat3(x, y, cross(x, y));
#endif
#endif
  v_normal = normal_matrix * n;
#if LIGHTING == 2
  v_prt = prt_radiance(model_rotation * skin_rotation);
#else
  v_prt = vec3(0.0);
#endif
  // Assimp's texture coordinates have v = 0 at the image's bottom; textures are uploaded top
  // row first.
  v_uv = vec2(uv.x, 1.0 - uv.y);
  gl_Position = mvp * vec4(p, 1.0);
}
)";
}

std::string FragmentShader(const ProgramVariant& variant) {
  return VariantDefines(variant) + R"(
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_prt;
uniform sampler2D albedo;
uniform vec4 base_color;
uniform vec3 light;  // map frame, towards the light
uniform float key;
uniform float ambient;
uniform vec3 sh[9];
out vec4 frag_color;

// Ramamoorthi and Hanrahan 2001: irradiance from order-2 SH, divided by pi (Lambertian radiance / albedo).
vec3 sh_irradiance(vec3 n) {
  const float a0 = 3.14159265358979, a1 = 2.09439510239320, a2 = 0.785398163397448;
  vec3 e = a0 * 0.282094791773878 * sh[0] +
           a1 * 0.488602511902920 * (sh[1] * n.y + sh[2] * n.z + sh[3] * n.x) +
           a2 * (1.092548430592079 * (sh[4] * n.x * n.y + sh[5] * n.y * n.z + sh[7] * n.x * n.z) +
                 0.315391565252520 * sh[6] * (3.0 * n.z * n.z - 1.0) +
                 0.546274215296040 * sh[8] * (n.x * n.x - n.y * n.y));
  return max(e, vec3(0.0)) / 3.14159265358979;
}

void main() {
#if TEXTURED
  vec4 c = texture(albedo, v_uv) * base_color;
#else
  vec4 c = base_color;  // a mesh without a texture: llvmpipe's texture fetch was ~15% of the layer
#endif
#if LIGHTING == 2
  vec3 shade = v_prt;
#else
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
#if LIGHTING == 1
  vec3 shade = sh_irradiance(n);
#else
  vec3 shade = vec3(ambient + key * max(dot(n, light), 0.0));
#endif
#endif
  frag_color = vec4(c.rgb * shade, 1.0);
}
)";
}

cv::Mat DecodeTexture(const anim::Texture& t, const std::string& source) {
  if (!t.rgba.empty()) {
    if (t.width <= 0 || t.height <= 0 || t.rgba.size() != static_cast<size_t>(t.width) * t.height * 4) {
      throw RenderError(source + ": raw texture has inconsistent size");
    }
    cv::Mat image;
    const cv::Mat rgba(t.height, t.width, CV_8UC4, const_cast<std::uint8_t*>(t.rgba.data()));
    cv::cvtColor(rgba, image, cv::COLOR_RGBA2BGRA);
    return image;
  }
  // Through base's checked reader: a cut or damaged texture is one error naming it (and the
  // asset), where cv::imread/imdecode let libpng and libjpeg print their own lines first.
  try {
    if (!t.encoded.empty()) {
      const std::string_view bytes(reinterpret_cast<const char*>(t.encoded.data()), t.encoded.size());
      return DecodeImageBytes(bytes, source + " (its embedded texture)", cv::IMREAD_COLOR);
    }
    if (!t.path.empty()) return ReadImageFile(t.path, cv::IMREAD_COLOR);
  } catch (const Error& e) {
    throw RenderError(t.encoded.empty() ? std::string(e.what()) + " (a texture of " + source + ")" : e.what());
  }
  throw RenderError(source + ": a texture without an image (no pixels, data or file)");
}

// Characters are mostly seen face-on: trilinear filtering suffices, and llvmpipe's anisotropic
// filtering is costly (measured with bench_render).
constexpr float kCharacterAnisotropy = 1.f;

int MaxJoints(const GlApi& gl) {
  // skin (16 floats) + two vec4 per joint, with room for the other uniforms.
  GLint components = 0;
  gl.GetIntegerv(GL_MAX_VERTEX_UNIFORM_COMPONENTS, &components);
  return (components - 64) / 24;
}

}  // namespace

CharacterRenderer::CharacterRenderer(const GlApi& gl, const anim::Character& character) : gl_(&gl) {
  joints_ = std::max(1, character.skeleton.size());
  if (joints_ > MaxJoints(gl)) {
    throw RenderError(character.source + ": " + std::to_string(joints_) + " joints; the vertex shader takes at most " +
                      std::to_string(MaxJoints(gl)));
  }
  // The default ones, so that a shader error shows here.
  ProgramFor(true, LightingMode::kFixed, true);
  ProgramFor(true, LightingMode::kFixed, false);
  for (const anim::Texture& t : character.textures) {
    textures_.push_back(MakeTexture(gl, DecodeTexture(t, character.source), {true, kCharacterAnisotropy, true}));
  }

  joint_radii_.assign(joints_, 0.f);
  std::vector<Eigen::Matrix4f> inverse_bind(joints_, Eigen::Matrix4f::Identity());
  for (int j = 0; j < std::min(joints_, static_cast<int>(character.skeleton.inverse_bind.size())); ++j) {
    inverse_bind[j] = character.skeleton.inverse_bind[j].cast<float>();
  }
  morph_targets_ = character.skeleton.morph_target_count();
  morph_candidates_.reserve(morph_targets_);
  for (const anim::Mesh& mesh : character.meshes) {
    const size_t n = mesh.positions.size();
    if (mesh.normals.size() != n || mesh.joints.size() != n || mesh.weights.size() != n ||
        (!mesh.uvs.empty() && mesh.uvs.size() != n)) {
      throw RenderError(character.source + ": mesh '" + mesh.name + "' has inconsistent vertex arrays");
    }
    std::vector<CharacterVertex> vertices(n);
    for (size_t i = 0; i < n; ++i) {
      CharacterVertex& v = vertices[i];
      for (int k = 0; k < 3; ++k) {
        v.position[k] = mesh.positions[i][k];
        v.normal[k] = mesh.normals[i][k];
      }
      v.uv[0] = mesh.uvs.empty() ? 0.f : mesh.uvs[i].x();
      v.uv[1] = mesh.uvs.empty() ? 0.f : mesh.uvs[i].y();
      for (int k = 0; k < 4; ++k) {
        if (mesh.joints[i][k] >= joints_) {
          throw RenderError(character.source + ": mesh '" + mesh.name + "' refers to joint " +
                            std::to_string(mesh.joints[i][k]) + " of " + std::to_string(joints_));
        }
        v.joints[k] = mesh.joints[i][k];
        v.weights[k] = mesh.weights[i][k];
        if (v.weights[k] > 0) {
          const int j = v.joints[k];
          const float d = (inverse_bind[j] * mesh.positions[i].homogeneous()).head<3>().norm();
          joint_radii_[j] = std::max(joint_radii_[j], d);
        }
      }
    }
    for (std::uint32_t index : mesh.indices) {
      if (index >= n) throw RenderError(character.source + ": mesh '" + mesh.name + "' has an index out of range");
    }
    GpuMesh gpu;
    gpu.vao = MakeVertexArray(gl);
    gl.BindVertexArray(gpu.vao.get());
    gpu.vbo = MakeBuffer(gl, GL_ARRAY_BUFFER, vertices.data(), vertices.size() * sizeof(CharacterVertex));
    gpu.ibo = MakeBuffer(gl, GL_ELEMENT_ARRAY_BUFFER, mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
    PointAtCharacterVertices(gl, true);
    gl.BindVertexArray(0);
    UploadMorphs(mesh, character.source, gpu);
    AddMorphReach(mesh, inverse_bind);
    gpu.index_count = static_cast<GLsizei>(mesh.indices.size());
    gpu.vertex_count = static_cast<int>(n);
    triangles_ += gpu.index_count / 3;
    if (mesh.material >= 0 && mesh.material < static_cast<int>(character.materials.size())) {
      const anim::Material& material = character.materials[mesh.material];
      gpu.base_color = material.base_color;
      if (material.texture >= 0 && material.texture < static_cast<int>(textures_.size())) gpu.texture = material.texture;
    }
    meshes_.push_back(std::move(gpu));
  }
  dq_upload_.resize(static_cast<size_t>(joints_) * 8);
  CheckGl(gl, "character upload (" + character.source + ")");
}

void CharacterRenderer::UploadMorphs(const anim::Mesh& mesh, const std::string& source, GpuMesh& gpu) {
  if (mesh.morphs.empty()) return;
  const GlApi& gl = *gl_;
  const size_t n = mesh.positions.size();
  const std::string where = source + ": mesh '" + mesh.name + "'";
  gpu.morph_base.assign(morph_targets_, -1);
  std::vector<float> texels(mesh.morphs.size() * 2 * n * 3, 0.f);
  for (size_t i = 0; i < mesh.morphs.size(); ++i) {
    const anim::MeshMorph& m = mesh.morphs[i];
    if (m.target < 0 || m.target >= morph_targets_ || gpu.morph_base[m.target] >= 0 ||
        m.position_deltas.size() != m.vertices.size() || m.normal_deltas.size() != m.vertices.size()) {
      throw RenderError(where + " has morph deltas that do not fit the character's targets");
    }
    const size_t base = i * 2 * n;
    gpu.morph_base[m.target] = static_cast<int>(base);
    for (size_t k = 0; k < m.vertices.size(); ++k) {
      const size_t v = m.vertices[k];
      if (v >= n) throw RenderError(where + " has a morph delta for vertex " + std::to_string(v) + " of " + std::to_string(n));
      std::copy_n(m.position_deltas[k].data(), 3, &texels[(base + v) * 3]);
      std::copy_n(m.normal_deltas[k].data(), 3, &texels[(base + n + v) * 3]);
    }
  }
  GLint max_texels = 0;
  gl.GetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
  if (texels.size() / 3 > static_cast<size_t>(max_texels)) {
    throw RenderError(where + ": " + std::to_string(mesh.morphs.size()) + " morph targets of " + std::to_string(n) +
                      " vertices exceed the buffer texture's " + std::to_string(max_texels) + " texels");
  }
  gpu.morph_buffer = MakeBuffer(gl, GL_TEXTURE_BUFFER, texels.data(), texels.size() * sizeof(float));
  gl.BindBuffer(GL_TEXTURE_BUFFER, 0);
  gpu.morph_texture = MakeBufferTexture(gl, gpu.morph_buffer.get(), GL_RGB32F);
  MakeCpuMorphPath(mesh, gpu);
}

void CharacterRenderer::MakeCpuMorphPath(const anim::Mesh& mesh, GpuMesh& gpu) {
  const GlApi& gl = *gl_;
  gpu.cpu_morphs = std::make_unique<CpuMorphs>(mesh, morph_targets_);
  gpu.morphed_vao = MakeVertexArray(gl);
  gl.BindVertexArray(gpu.morphed_vao.get());
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.ibo.get());  // the mesh's triangles, as in its own vertex array
  const size_t floats = mesh.positions.size() * CpuMorphs::kFloatsPerVertex;
  gpu.morphed_vbo = MakeBuffer(gl, GL_ARRAY_BUFFER, nullptr, floats * sizeof(float), GL_STREAM_DRAW);
  const auto morphed_stride = static_cast<GLsizei>(CpuMorphs::kFloatsPerVertex * sizeof(float));
  for (GLuint location : {0u, 1u}) {  // position, normal
    gl.EnableVertexAttribArray(location);
    gl.VertexAttribPointer(location, 3, GL_FLOAT, GL_FALSE, morphed_stride,
                           reinterpret_cast<void*>(location * 3 * sizeof(float)));
  }
  gl.BindBuffer(GL_ARRAY_BUFFER, gpu.vbo.get());
  PointAtCharacterVertices(gl, false);
  gl.BindVertexArray(0);
}

bool CharacterRenderer::MorphOnCpu(GpuMesh& mesh, int count) {
  if (!mesh.cpu_morphs || count == 0) return false;
  const std::span<const int> targets(active_target_.data(), static_cast<size_t>(count));
  if (mesh.cpu_morphs->DeltaCount(targets) > static_cast<size_t>(std::max(cpu_morph_max_deltas_, 0))) return false;
  const std::span<const float> morphed =
      mesh.cpu_morphs->Apply(targets, std::span<const float>(active_weight_.data(), static_cast<size_t>(count)));
  const GlApi& gl = *gl_;
  gl.BindBuffer(GL_ARRAY_BUFFER, mesh.morphed_vbo.get());
  gl.BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(morphed.size_bytes()), morphed.data());
  ++morphed_on_cpu_;
  return true;
}

void CharacterRenderer::AddMorphReach(const anim::Mesh& mesh, const std::vector<Eigen::Matrix4f>& inverse_bind) {
  if (mesh.morphs.empty()) return;
  morph_reach_.resize(static_cast<size_t>(morph_targets_) * joints_, 0.f);
  frame_radii_.resize(joints_);
  for (const anim::MeshMorph& m : mesh.morphs) {
    for (size_t i = 0; i < m.vertices.size(); ++i) {
      const size_t v = m.vertices[i];
      for (int k = 0; k < 4; ++k) {
        if (mesh.weights[v][k] <= 0) continue;
        const int j = mesh.joints[v][k];
        float& reach = morph_reach_[static_cast<size_t>(m.target) * joints_ + j];
        reach = std::max(reach, (inverse_bind[j].topLeftCorner<3, 3>() * m.position_deltas[i]).norm());
      }
    }
  }
}

std::span<const float> CharacterRenderer::JointRadii(std::span<const float> morph_weights) {
  if (morph_reach_.empty() || morph_weights.size() != static_cast<size_t>(morph_targets_)) return joint_radii_;
  std::copy(joint_radii_.begin(), joint_radii_.end(), frame_radii_.begin());
  for (int t = 0; t < morph_targets_; ++t) {
    const float w = std::abs(morph_weights[t]);
    if (w == 0.f || !std::isfinite(w)) continue;
    const float* reach = &morph_reach_[static_cast<size_t>(t) * joints_];
    for (int j = 0; j < joints_; ++j) frame_radii_[j] += w * reach[j];
  }
  return frame_radii_;
}

int CharacterRenderer::ActiveMorphs(const GpuMesh& mesh, std::span<const float> weights) {
  if (mesh.morph_base.empty() || weights.empty()) return 0;
  morph_candidates_.clear();  // reserved for every target: no allocation
  for (size_t k = 0; k < weights.size() && k < mesh.morph_base.size(); ++k) {
    if (weights[k] != 0.f && std::isfinite(weights[k]) && mesh.morph_base[k] >= 0) {
      morph_candidates_.emplace_back(std::abs(weights[k]), static_cast<int>(k));
    }
  }
  int count = static_cast<int>(morph_candidates_.size());
  if (count > kMaxActiveMorphTargets) {
    std::nth_element(morph_candidates_.begin(), morph_candidates_.begin() + kMaxActiveMorphTargets, morph_candidates_.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    morph_dropped_ += count - kMaxActiveMorphTargets;
    count = kMaxActiveMorphTargets;
  }
  for (int i = 0; i < count; ++i) {
    const int target = morph_candidates_[i].second;
    active_base_[i] = mesh.morph_base[target];
    active_weight_[i] = weights[target];
    active_target_[i] = target;
  }
  morph_applied_ += count;
  return count;
}

const CharacterRenderer::Program& CharacterRenderer::ProgramFor(bool dual_quaternion, LightingMode lighting, bool textured,
                                                                bool morphed) {
  const ProgramVariant variant{dual_quaternion, lighting, textured, morphed};
  std::unique_ptr<Program>& slot = programs_.at(variant.Index());
  if (slot) return *slot;
  const GlApi& gl = *gl_;
  auto program = std::make_unique<Program>();
  program->program = MakeProgram(gl, "character", VertexShader(joints_, variant), FragmentShader(variant));
  const GLuint p = program->program.get();
  program->loc = {Uniform(gl, p, "mvp"),        Uniform(gl, p, "model"),   Uniform(gl, p, "normal_matrix"),
                  Uniform(gl, p, "skin"),       Uniform(gl, p, "dq_real"), Uniform(gl, p, "dq_dual"),
                  Uniform(gl, p, "light"),      Uniform(gl, p, "key"),     Uniform(gl, p, "ambient"),
                  Uniform(gl, p, "base_color"), Uniform(gl, p, "albedo"),  Uniform(gl, p, "model_rotation"),
                  Uniform(gl, p, "sh"),         Uniform(gl, p, "morph_deltas"), Uniform(gl, p, "morph_count"),
                  Uniform(gl, p, "morph_base"), Uniform(gl, p, "morph_weight"), Uniform(gl, p, "morph_vertices")};
  slot = std::move(program);
  return *slot;
}

void CharacterRenderer::SetTransfer(const CharacterTransfer& transfer) {
  const GlApi& gl = *gl_;
  if (transfer.meshes.size() != meshes_.size()) {
    throw RenderError("PRT transfer has " + std::to_string(transfer.meshes.size()) + " meshes, the character " +
                      std::to_string(meshes_.size()));
  }
  for (size_t m = 0; m < meshes_.size(); ++m) {
    if (static_cast<int>(transfer.meshes[m].size()) != meshes_[m].vertex_count) {
      throw RenderError("PRT transfer of mesh " + std::to_string(m) + " has " + std::to_string(transfer.meshes[m].size()) +
                        " vertices, the mesh " + std::to_string(meshes_[m].vertex_count));
    }
  }
  for (size_t m = 0; m < meshes_.size(); ++m) {
    GpuMesh& mesh = meshes_[m];
    mesh.transfer_vbo = MakeBuffer(gl, GL_ARRAY_BUFFER, transfer.meshes[m].data(), transfer.meshes[m].size() * sizeof(Sh9f));
    for (const GlName* vao : {&mesh.vao, &mesh.morphed_vao}) {
      if (!vao->get()) continue;  // no CPU morph path
      gl.BindVertexArray(vao->get());
      gl.BindBuffer(GL_ARRAY_BUFFER, mesh.transfer_vbo.get());
      for (GLuint k = 0; k < 3; ++k) {
        gl.EnableVertexAttribArray(5 + k);
        gl.VertexAttribPointer(5 + k, 3, GL_FLOAT, GL_FALSE, sizeof(Sh9f), reinterpret_cast<void*>(k * 3 * sizeof(float)));
      }
    }
    gl.BindVertexArray(0);
  }
  has_transfer_ = true;
  CheckGl(gl, "PRT transfer upload");
}

void CharacterRenderer::Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, const CharacterDraw& d) {
  const GlApi& gl = *gl_;
  if (static_cast<int>(d.skinning_matrices.size()) != joints_ ||
      (d.method == anim::SkinningMethod::kDualQuaternion && static_cast<int>(d.skinning_dual_quats.size()) != joints_)) {
    throw RenderError("character draw: " + std::to_string(joints_) + " skinning transforms expected");
  }
  if (!d.morph_weights.empty() && static_cast<int>(d.morph_weights.size()) != morph_targets_) {
    throw RenderError("character draw: " + std::to_string(d.morph_weights.size()) + " morph weights for " +
                      std::to_string(morph_targets_) + " targets");
  }
  morph_applied_ = morph_dropped_ = morphed_on_cpu_ = 0;
  // DQ skinning drops scale; with scaled joints linear blend is the correct one.
  const bool dual = d.method == anim::SkinningMethod::kDualQuaternion && anim::RigidSkinning(d.skinning_matrices);
  used_linear_fallback_ = d.method == anim::SkinningMethod::kDualQuaternion && !dual;

  DrawUniforms u;
  u.dual = dual;
  u.mvp = (projection * view * d.model_to_map).cast<float>();
  u.model = d.model_to_map.cast<float>();
  u.normal_matrix = d.model_to_map.topLeftCorner<3, 3>().inverse().transpose().cast<float>();
  u.light = d.light_direction_map.normalized().cast<float>();

  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  gl.DepthMask(GL_TRUE);
  gl.Disable(GL_BLEND);
  if (d.cull_back_faces) {
    // Front faces are counter-clockwise in model space; a mirroring placement reverses that.
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.FrontFace(d.model_to_map.topLeftCorner<3, 3>().determinant() < 0 ? GL_CW : GL_CCW);
  } else {
    gl.Disable(GL_CULL_FACE);
  }
  u.lighting = d.lighting == LightingMode::kShShadowed && !has_transfer_ ? LightingMode::kShUnshadowed : d.lighting;
  for (int k = 0; k < 9; ++k)
    for (int c = 0; c < 3; ++c) u.sh[3 * k + c] = static_cast<float>(d.sh[k][c]);
  Eigen::Matrix3d rotation = d.model_to_map.topLeftCorner<3, 3>();
  rotation /= std::cbrt(std::abs(rotation.determinant()));  // uniform scale out
  u.model_rotation = rotation.cast<float>();
  if (dual) {
    for (int j = 0; j < joints_; ++j) {
      const anim::DualQuatf& q = d.skinning_dual_quats[j];
      std::copy_n(q.real().coeffs().data(), 4, &dq_upload_[j * 4]);
      std::copy_n(q.dual().coeffs().data(), 4, &dq_upload_[(joints_ + j) * 4]);
    }
  }
  // The textured meshes, then those of one colour, each with its program (when it has any).
  gl.ActiveTexture(GL_TEXTURE0);
  for (const bool textured : {true, false}) {
    const Program* bound = nullptr;
    for (GpuMesh& mesh : meshes_) {
      if ((mesh.texture >= 0) != textured) continue;
      int morphs = ActiveMorphs(mesh, d.morph_weights);
      const bool on_cpu = MorphOnCpu(mesh, morphs);
      if (on_cpu) morphs = 0;  // the shader's part done
      const Program& program = ProgramFor(dual, u.lighting, textured, morphs > 0);
      if (bound != &program) bound = &UseProgram(program, u, d);
      if (textured) gl.BindTexture(GL_TEXTURE_2D, textures_[mesh.texture].get());
      if (morphs > 0) {
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_BUFFER, mesh.morph_texture.get());
        gl.ActiveTexture(GL_TEXTURE0);
        gl.Uniform1i(bound->loc.morph_count, morphs);
        gl.Uniform1iv(bound->loc.morph_base, morphs, active_base_.data());
        gl.Uniform1fv(bound->loc.morph_weight, morphs, active_weight_.data());
        gl.Uniform1i(bound->loc.morph_vertices, mesh.vertex_count);
      }
      gl.Uniform4f(bound->loc.base_color, mesh.base_color[0], mesh.base_color[1], mesh.base_color[2], mesh.base_color[3]);
      gl.BindVertexArray(on_cpu ? mesh.morphed_vao.get() : mesh.vao.get());
      gl.DrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
    }
  }
  gl.BindVertexArray(0);
}

const CharacterRenderer::Program& CharacterRenderer::UseProgram(const Program& program, const DrawUniforms& u,
                                                                const CharacterDraw& d) {
  const GlApi& gl = *gl_;
  const Locations& loc = program.loc;
  gl.UseProgram(program.program.get());
  gl.UniformMatrix4fv(loc.mvp, 1, GL_FALSE, u.mvp.data());
  gl.UniformMatrix4fv(loc.model, 1, GL_FALSE, u.model.data());
  gl.UniformMatrix3fv(loc.normal_matrix, 1, GL_FALSE, u.normal_matrix.data());
  if (u.dual) {
    gl.Uniform4fv(loc.dq_real, joints_, dq_upload_.data());
    gl.Uniform4fv(loc.dq_dual, joints_, dq_upload_.data() + joints_ * 4);
  } else {
    gl.UniformMatrix4fv(loc.skin, joints_, GL_FALSE, d.skinning_matrices.data()->data());
  }
  if (u.lighting != LightingMode::kFixed) {
    gl.Uniform3fv(loc.sh, 9, u.sh);
    gl.UniformMatrix3fv(loc.model_rotation, 1, GL_FALSE, u.model_rotation.data());
  }
  gl.Uniform3f(loc.light, u.light.x(), u.light.y(), u.light.z());
  gl.Uniform1f(loc.key, d.key);
  gl.Uniform1f(loc.ambient, d.ambient);
  gl.Uniform1i(loc.albedo, 0);
  if (loc.morph_deltas >= 0) gl.Uniform1i(loc.morph_deltas, 1);  // texture unit 1
  return program;
}

LightingMode ParseLightingMode(const std::string& name) {
  if (name == "fixed") return LightingMode::kFixed;
  if (name == "sh") return LightingMode::kShUnshadowed;
  if (name == "prt") return LightingMode::kShShadowed;
  throw RenderError("unknown lighting '" + name + "' (expected fixed, sh or prt)");
}

std::string LightingModeName(LightingMode mode) {
  switch (mode) {
    case LightingMode::kFixed: return "fixed";
    case LightingMode::kShUnshadowed: return "sh";
    case LightingMode::kShShadowed: return "prt";
  }
  return "?";
}

namespace {

const char* kShadowVertex = R"(#version 450 core
layout(location = 0) in vec2 corner;  // (±1, ±1)
uniform mat4 mvp;                     // maps (u, v, 1) to clip space through the plane's frame
out vec2 v_corner;
void main() {
  v_corner = corner;
  gl_Position = mvp * vec4(corner, 0.0, 1.0);
}
)";

const char* kShadowFragment = R"(#version 450 core
in vec2 v_corner;
uniform float strength;
out vec4 frag_color;
void main() {
  float r = length(v_corner);
  // Dark under the character, fading smoothly to nothing at the rim.
  float a = strength * (1.0 - smoothstep(0.15, 1.0, r));
  frag_color = vec4(0.0, 0.0, 0.0, a);
}
)";

}  // namespace

ContactShadow::ContactShadow(const GlApi& gl) : gl_(&gl) {
  program_ = MakeProgram(gl, "contact shadow", kShadowVertex, kShadowFragment);
  mvp_ = Uniform(gl, program_.get(), "mvp");
  strength_ = Uniform(gl, program_.get(), "strength");
  const float corners[] = {-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1};
  vao_ = MakeVertexArray(gl);
  gl.BindVertexArray(vao_.get());
  vbo_ = MakeBuffer(gl, GL_ARRAY_BUFFER, corners, sizeof corners);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  gl.BindVertexArray(0);
}

void ContactShadow::Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, const Eigen::Vector3d& center,
                         const Eigen::Vector3d& axis_u, const Eigen::Vector3d& axis_v, float strength) {
  const GlApi& gl = *gl_;
  Eigen::Matrix4d plane = Eigen::Matrix4d::Identity();
  plane.col(0).head<3>() = axis_u;
  plane.col(1).head<3>() = axis_v;
  plane.col(2).head<3>() = axis_u.cross(axis_v).normalized();
  plane.col(3).head<3>() = center;
  const Eigen::Matrix4f mvp = (projection * view * plane).cast<float>();
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthMask(GL_FALSE);
  gl.Enable(GL_BLEND);
  // Premultiplied: colour stays black, alpha accumulates; the layer is blended over the video.
  gl.BlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  gl.UseProgram(program_.get());
  gl.UniformMatrix4fv(mvp_, 1, GL_FALSE, mvp.data());
  gl.Uniform1f(strength_, strength);
  gl.BindVertexArray(vao_.get());
  gl.DrawArrays(GL_TRIANGLES, 0, 6);
  gl.BindVertexArray(0);
  gl.Disable(GL_BLEND);
  gl.DepthMask(GL_TRUE);
}

}  // namespace arview::render
