// arview anim info <asset> [--json]
// arview anim weights --scene <scene.yaml> --viewpoint x,y,z [--character <name>] [--time s] [--json]

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "anim_authoring/animator_builder.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/lookat.h"
#include "anim_authoring/import.h"
#include "anim_authoring/scene.h"
#include "app/cli/commands.h"

namespace arview::app {

namespace {

struct AnimArgs {
  std::string asset;
  std::string scene;
  std::string viewpoint;
  std::string character;
  double time = 0;
  bool json = false;
};

std::string Fixed(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

int Depth(const anim::Skeleton& sk, int j) {
  int d = 0;
  for (; sk.parents[j] >= 0; j = sk.parents[j]) ++d;
  return d;
}

// Joints of the skeleton that a mesh's vertices reference.
int BonesUsed(const anim::Mesh& mesh, int joints) {
  std::vector<bool> used(joints, false);
  for (std::size_t v = 0; v < mesh.joints.size(); ++v)
    for (int i = 0; i < 4; ++i)
      if (mesh.weights[v][i] > 0) used[mesh.joints[v][i]] = true;
  int n = 0;
  for (bool u : used) n += u;
  return n;
}

// How many vertices a morph target moves, over every mesh.
std::size_t VerticesMoved(const anim::Character& c, int target) {
  std::size_t n = 0;
  for (const anim::Mesh& m : c.meshes)
    for (const anim::MeshMorph& morph : m.morphs)
      if (morph.target == target) n += morph.vertices.size();
  return n;
}

// The names of the targets a clip's weight tracks key.
std::vector<std::string> WeightTrackNames(const anim::Character& c, const anim::Clip& clip) {
  std::vector<std::string> names;
  for (const anim::WeightTrack& t : clip.weight_tracks) names.push_back(c.skeleton.morph_targets[t.target]);
  return names;
}

std::string TextureText(const anim::Character& c, int texture) {
  if (texture < 0) return "none";
  const anim::Texture& t = c.textures[texture];
  if (!t.path.empty()) return t.path;
  if (!t.encoded.empty()) return "embedded " + t.format_hint + " (" + std::to_string(t.encoded.size()) + " bytes)";
  return "embedded raw " + std::to_string(t.width) + "x" + std::to_string(t.height);
}

void RunInfo(const AnimArgs& args) {
  const anim::Character c = authoring::LoadCharacter(args.asset);
  const anim::Skeleton& sk = c.skeleton;
  const std::vector<std::string> chain = authoring::DefaultLookAtChain(sk);
  if (args.json) {
    nlohmann::ordered_json j = {{"asset", c.source}};
    nlohmann::ordered_json& joints = j["joints"] = nlohmann::ordered_json::array();
    for (int i = 0; i < sk.size(); ++i) joints.push_back({{"index", i}, {"name", sk.names[i]}, {"parent", sk.parents[i]}});
    nlohmann::ordered_json& clips = j["clips"] = nlohmann::ordered_json::array();
    for (const anim::Clip& clip : c.clips)
      clips.push_back({{"name", clip.name},
                       {"duration_s", clip.duration},
                       {"ticks_per_second", clip.ticks_per_second},
                       {"weight_tracks", WeightTrackNames(c, clip)}});
    nlohmann::ordered_json& targets = j["morph_targets"] = nlohmann::ordered_json::array();
    for (int k = 0; k < sk.morph_target_count(); ++k)
      targets.push_back({{"index", k}, {"name", sk.morph_targets[k]}, {"vertices", VerticesMoved(c, k)}});
    nlohmann::ordered_json& meshes = j["meshes"] = nlohmann::ordered_json::array();
    for (const anim::Mesh& m : c.meshes) {
      nlohmann::ordered_json mesh = {{"name", m.name},
                                     {"vertices", m.positions.size()},
                                     {"triangles", m.indices.size() / 3},
                                     {"bones", BonesUsed(m, sk.size())},
                                     {"uvs", !m.uvs.empty()},
                                     {"material", m.material}};
      if (m.material >= 0) mesh["texture"] = TextureText(c, c.materials[m.material].texture);
      meshes.push_back(std::move(mesh));
    }
    nlohmann::ordered_json& chain_json = j["default_lookat_chain"] = nlohmann::ordered_json::array();
    for (const std::string& n : chain) chain_json.push_back({{"joint", n}});
    nlohmann::ordered_json& arms = j["default_arm_chains"] = nlohmann::ordered_json::object();
    for (authoring::ArmSide side : {authoring::ArmSide::kRight, authoring::ArmSide::kLeft})
      arms[std::string(ToString(side))] = authoring::DefaultArmChain(sk, side);
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << c.source << "\n";
  std::cout << "skeleton: " << sk.size() << " joints\n";
  for (int i = 0; i < sk.size(); ++i)
    std::cout << "  " << std::string(2 * Depth(sk, i), ' ') << "[" << i << "] " << sk.names[i] << "\n";
  std::cout << "clips: " << c.clips.size() << "\n";
  for (const anim::Clip& clip : c.clips) {
    std::cout << "  " << clip.name << "  " << Fixed(clip.duration) << " s";
    if (clip.ticks_per_second > 0) std::cout << "  (" << Fixed(clip.ticks_per_second, 1) << " ticks/s)";
    const std::vector<std::string> weights = WeightTrackNames(c, clip);
    if (!weights.empty()) std::cout << "  weight tracks:";
    for (const std::string& name : weights) std::cout << " " << name;
    std::cout << "\n";
  }
  std::cout << "morph targets: " << sk.morph_target_count() << "\n";
  for (int k = 0; k < sk.morph_target_count(); ++k)
    std::cout << "  [" << k << "] " << sk.morph_targets[k] << ": " << VerticesMoved(c, k) << " vertices\n";
  std::cout << "meshes: " << c.meshes.size() << "\n";
  for (const anim::Mesh& m : c.meshes) {
    std::cout << "  " << (m.name.empty() ? "(unnamed)" : m.name) << ": " << m.positions.size() << " vertices, "
              << m.indices.size() / 3 << " triangles, " << BonesUsed(m, sk.size()) << " bones"
              << (m.uvs.empty() ? ", no UVs" : "");
    if (m.material >= 0) {
      const anim::Material& mat = c.materials[m.material];
      std::cout << ", base colour (" << Fixed(mat.base_color[0], 2) << ", " << Fixed(mat.base_color[1], 2) << ", "
                << Fixed(mat.base_color[2], 2) << "), texture " << TextureText(c, mat.texture);
    }
    std::cout << "\n";
  }
  std::cout << "default look-at chain: ";
  if (chain.empty()) std::cout << "none found (name the joints in the scene's lookat.chain)";
  for (std::size_t i = 0; i < chain.size(); ++i) std::cout << (i ? " > " : "") << chain[i];
  std::cout << "\n";
  for (authoring::ArmSide side : {authoring::ArmSide::kRight, authoring::ArmSide::kLeft}) {
    const std::vector<std::string> arm = authoring::DefaultArmChain(sk, side);
    std::cout << "default " << ToString(side) << " arm chain (gesture keys): ";
    if (arm.empty()) std::cout << "none found (name the joints in the scene's gesture.chain)";
    for (std::size_t i = 0; i < arm.size(); ++i) std::cout << (i ? " > " : "") << arm[i];
    std::cout << "\n";
  }
}

// "lookat", or "lookat+point" for a gesture key.
std::string SourceText(const authoring::KeySpec& key) {
  std::string s(ToString(key.source));
  if (key.gesture != authoring::Gesture::kNone) s += std::string("+") + std::string(ToString(key.gesture));
  return s;
}

void RunWeights(const AnimArgs& args) {
  const Eigen::Vector3d v = authoring::ParseViewpoint(args.viewpoint, "--viewpoint");
  if (!std::isfinite(args.time)) throw CommandError("--time must be a finite number of seconds");
  const authoring::Scene scene = authoring::LoadScene(args.scene);
  const authoring::CharacterSpec* spec = nullptr;
  for (const authoring::CharacterSpec& c : scene.characters)
    if (args.character.empty() || c.name == args.character) {
      spec = &c;
      break;
    }
  if (!spec) throw CommandError(args.scene + ": no character named '" + args.character + "'");
  authoring::AnimatedCharacter ch(*spec);
  const anim::AnimatorFrame& out = ch.Update(v, args.time);
  const bool lookat = !ch.lookat_chain().joints.empty();
  double head_deg = 0;
  if (lookat) {
    const Eigen::Vector3d f = anim::HeadForward(ch.lookat_chain(), out.model);
    head_deg = std::atan2(f.cross(v).norm(), f.dot(v)) * 180 / M_PI;
  }
  // Gesture keys: the arm's direction to the viewpoint, measured as the heaviest gesture key
  // aims it (point: the forearm; reach: shoulder to hand).
  const bool gesture = ch.arm_chain().upper >= 0;
  authoring::Gesture kind = authoring::Gesture::kNone;
  double heaviest = -1, arm_deg = 0;
  for (std::size_t k = 0; k < spec->keys.size(); ++k)
    if (spec->keys[k].gesture != authoring::Gesture::kNone && out.key_weights[k] > heaviest) {
      heaviest = out.key_weights[k];
      kind = spec->keys[k].gesture;
    }
  if (gesture) {
    const Eigen::Vector3d d = authoring::GestureDirection(ch.arm_chain(), kind, out.model);
    arm_deg = std::atan2(d.cross(v).norm(), d.dot(v)) * 180 / M_PI;
  }
  const bool dib = spec->blend == anim::BlendMethod::kDib;
  // The idle section learned as the appliance learns it: what the data gave each layer.
  authoring::IdleLayerReport idle;
  if (spec->idle.given) authoring::BuildIdleLayer(ch, &idle);
  const std::string balance_text =
      idle.balance + (idle.balance_built ? "" : "; the character idles without balance shifts");
  if (args.json) {
    nlohmann::ordered_json j = {{"scene", args.scene},
                                {"character", spec->name},
                                {"viewpoint", {v.x(), v.y(), v.z()}},
                                {"time_s", args.time}};
    nlohmann::ordered_json& keys = j["keys"] = nlohmann::ordered_json::array();
    for (std::size_t k = 0; k < spec->keys.size(); ++k) {
      const authoring::KeySpec& key = spec->keys[k];
      keys.push_back({{"index", k},
                      {"source", SourceText(key)},
                      {"clip", ch.key_clip(int(k)).name},
                      {"viewpoint", {key.viewpoint.x(), key.viewpoint.y(), key.viewpoint.z()}},
                      {"weight", out.key_weights[k]}});
    }
    j["blend"] = dib ? "dib" : "dlb";
    if (dib) {
      j["dib_converged"] = out.converged;
      j["dib_max_iterations"] = out.max_iterations;
    }
    if (lookat) j["head_to_viewpoint_deg"] = head_deg;
    if (gesture) {
      j["gesture"] = ToString(kind);
      j["arm_to_viewpoint_deg"] = arm_deg;
      j["elbow_bend_deg"] = authoring::ElbowBendDeg(ch.arm_chain(), out.model);
    }
    if (spec->idle.given) j["idle"] = idle.idle;
    if (spec->idle.balance.given) j["balance"] = {{"built", idle.balance_built}, {"summary", idle.balance}};
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << "character " << spec->name << ", viewpoint (" << Fixed(v.x()) << ", " << Fixed(v.y()) << ", "
            << Fixed(v.z()) << "), t = " << Fixed(args.time) << " s\n";
  for (std::size_t k = 0; k < spec->keys.size(); ++k) {
    const authoring::KeySpec& key = spec->keys[k];
    std::cout << "  key " << k << "  (" << Fixed(key.viewpoint.x()) << ", " << Fixed(key.viewpoint.y()) << ", "
              << Fixed(key.viewpoint.z()) << ")  " << SourceText(key) << " " << ch.key_clip(int(k)).name
              << "  weight " << Fixed(out.key_weights[k], 4) << "\n";
  }
  if (dib)
    std::cout << "DIB: " << (out.converged ? "converged" : "NOT converged") << ", at most " << out.max_iterations
              << " iterations per joint\n";
  if (lookat) std::cout << "head forward to viewpoint: " << Fixed(head_deg, 2) << " deg\n";
  if (gesture)
    std::cout << ToString(spec->gesture.side) << " arm (" << ToString(kind) << ") to viewpoint: " << Fixed(arm_deg, 2)
              << " deg, elbow bend " << Fixed(authoring::ElbowBendDeg(ch.arm_chain(), out.model), 1) << " deg\n";
  if (spec->idle.given) std::cout << "idle: " << idle.idle << "\n";
  if (spec->idle.balance.given) std::cout << "balance: " << balance_text << "\n";
}


}  // namespace

void AddAnimCommand(CLI::App& app) {
  auto args = std::make_shared<AnimArgs>();
  auto* cmd = app.add_subcommand("anim", "Inspect characters and view-adaptive blend weights ('anim info', 'anim weights')");
  cmd->require_subcommand(1);

  auto* info = cmd->add_subcommand(
      "info", "Skeleton, clips (with their morph target weight tracks), morph targets, meshes and bones per mesh of a character asset");
  info->add_option("asset", args->asset, "Character file (glTF .glb/.gltf, FBX, Collada .dae, DirectX .X, BVH)")->required();
  info->add_flag("--json", args->json, "Print JSON instead of text");
  info->callback([args] { RunInfo(*args); });

  auto* weights = cmd->add_subcommand(
      "weights", "Key weights (and the blended head's and gesturing arm's directions) for one viewpoint; what the idle section learns");
  weights->add_option("--scene", args->scene, "Scene file (YAML, see docs/anim.md)")->required();
  weights->add_option("--viewpoint", args->viewpoint, "Direction from the character to the viewer, x,y,z in the character's frame")
      ->required();
  weights->add_option("--character", args->character, "Character name in the scene (default: the first)");
  weights->add_option("--time", args->time, "Animation time in seconds (default 0)");
  weights->add_flag("--json", args->json, "Print JSON instead of text");
  weights->callback([args] { RunWeights(*args); });
}

}  // namespace arview::app
