#include "anim/scene.h"

#include "anim/yaml.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace arview::anim {
namespace {

namespace fs = std::filesystem;
using yaml::Node;

class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(const Node& n, const std::string& what) const {
    throw Error(file_ + ":" + std::to_string(n.line) + ": " + what);
  }

  void OnlyKeys(const Node& n, const std::set<std::string>& allowed, const std::string& where) const {
    if (!n.IsMapping()) Fail(n, where + " must be a mapping");
    for (const auto& [k, v] : n.entries)
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(v, "unknown key '" + k + "' in " + where + " (known: " + list + ")");
      }
  }

  double Number(const Node& n, const std::string& what) const {
    if (!n.IsScalar() || n.scalar.empty()) Fail(n, what + ": expected a number");
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(n.scalar, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != n.scalar.size() || !std::isfinite(x)) Fail(n, what + ": expected a number, got '" + n.scalar + "'");
    return x;
  }

  std::string String(const Node& n, const std::string& what) const {
    if (!n.IsScalar() || n.scalar.empty()) Fail(n, what + ": expected a non-empty string");
    return n.scalar;
  }

  std::vector<double> Numbers(const Node& n, const std::string& what, std::size_t count = 0) const {
    if (!n.IsSequence()) Fail(n, what + ": expected a list like [1, 2, 3]");
    if (count && n.items.size() != count)
      Fail(n, what + ": expected " + std::to_string(count) + " numbers, got " + std::to_string(n.items.size()));
    std::vector<double> out;
    for (const Node& x : n.items) out.push_back(Number(x, what));
    return out;
  }

  Eigen::Vector3d Vec3(const Node& n, const std::string& what) const {
    const auto v = Numbers(n, what, 3);
    return {v[0], v[1], v[2]};
  }

  Eigen::Vector3d Direction(const Node& n, const std::string& what) const {
    const Eigen::Vector3d v = Vec3(n, what);
    if (v.norm() < 1e-9) Fail(n, what + " has zero length");
    return v.normalized();
  }

  template <class E>
  E Choice(const Node& n, const std::string& what, const std::vector<std::pair<std::string, E>>& options) const {
    const std::string s = String(n, what);
    std::string list;
    for (const auto& [name, value] : options) {
      if (s == name) return value;
      list += (list.empty() ? "" : " | ") + name;
    }
    Fail(n, what + ": '" + s + "' is not one of " + list);
  }

  CharacterSpec Character(const Node& n, const fs::path& base_dir) const {
    OnlyKeys(n, {"name", "asset", "scale", "anchor", "forward", "up", "weights", "blend", "phase", "sampling", "lookat", "keys"},
             "a character");
    CharacterSpec c;
    c.where = file_ + ":" + std::to_string(n.line);
    if (const Node* x = n.Find("name")) c.name = String(*x, "name");
    const Node* asset = n.Find("asset");
    if (!asset) Fail(n, "a character needs 'asset: <file>'");
    fs::path a = String(*asset, "asset");
    if (a.is_relative()) a = base_dir / a;
    c.asset = fs::absolute(a).lexically_normal();
    if (c.name.empty()) c.name = c.asset.stem().string();
    if (const Node* x = n.Find("scale")) {
      c.scale = Number(*x, "scale");
      if (!(c.scale > 0)) Fail(*x, "scale must be positive");
    }
    if (const Node* x = n.Find("anchor")) c.anchor = AnchorOf(*x);
    if (const Node* x = n.Find("forward")) c.forward = Direction(*x, "forward");
    if (const Node* x = n.Find("up")) c.up = Direction(*x, "up");
    if (std::abs(c.forward.dot(c.up)) > 0.999) Fail(n, "forward and up must not be parallel");
    if (const Node* x = n.Find("weights")) {
      OnlyKeys(*x, {"mode", "distance", "alpha"}, "weights");
      if (const Node* y = x->Find("mode"))
        c.weights.mode = Choice<WeightingMode>(*y, "weights.mode",
                                               {{"inverse-distance", WeightingMode::kInverseDistance},
                                                {"local", WeightingMode::kLocalSupport}});
      if (const Node* y = x->Find("distance"))
        c.weights.distance = Choice<DistanceKind>(*y, "weights.distance",
                                                  {{"geodesic", DistanceKind::kGeodesic}, {"chordal", DistanceKind::kChordal}});
      if (const Node* y = x->Find("alpha")) {
        c.weights.alpha = Number(*y, "weights.alpha");
        if (!(c.weights.alpha > 0)) Fail(*y, "weights.alpha must be positive");
      }
    }
    if (const Node* x = n.Find("blend")) {
      OnlyKeys(*x, {"method", "precision", "max_iterations"}, "blend");
      if (const Node* y = x->Find("method"))
        c.blend = Choice<BlendMethod>(*y, "blend.method", {{"dlb", BlendMethod::kDlb}, {"dib", BlendMethod::kDib}});
      if (const Node* y = x->Find("precision")) {
        c.dib.precision = Number(*y, "blend.precision");
        if (!(c.dib.precision > 0)) Fail(*y, "blend.precision must be positive");
      }
      if (const Node* y = x->Find("max_iterations")) {
        const double it = Number(*y, "blend.max_iterations");
        if (it < 1 || it > 10000 || it != std::floor(it)) Fail(*y, "blend.max_iterations must be an integer in 1..10000");
        c.dib.max_iterations = static_cast<int>(it);
      }
    }
    if (const Node* x = n.Find("phase"))
      c.phase = Choice<PhaseMode>(*x, "phase", {{"shared", PhaseMode::kShared}, {"independent", PhaseMode::kIndependent}});
    if (const Node* x = n.Find("sampling"))
      c.nlerp_sampling = Choice<bool>(*x, "sampling", {{"slerp", false}, {"nlerp", true}});
    if (const Node* x = n.Find("lookat")) {
      OnlyKeys(*x, {"base_clip", "chain", "limits"}, "lookat");
      c.has_lookat = true;
      if (const Node* y = x->Find("base_clip")) c.lookat.base_clip = String(*y, "lookat.base_clip");
      if (const Node* y = x->Find("chain")) {
        if (!y->IsSequence() || y->items.empty()) Fail(*y, "lookat.chain: expected a list of joint names");
        for (const Node& j : y->items) c.lookat.chain.push_back(String(j, "lookat.chain"));
      }
      if (const Node* y = x->Find("limits")) {
        c.lookat.limits_deg = Numbers(*y, "lookat.limits");
        for (double l : c.lookat.limits_deg)
          if (!(l > 0) || l > 180) Fail(*y, "lookat.limits: each limit must be in (0, 180] degrees");
      }
    }
    const Node* keys = n.Find("keys");
    if (!keys || !keys->IsSequence() || keys->items.empty()) Fail(n, "a character needs a non-empty 'keys:' list");
    for (const Node& k : keys->items) c.keys.push_back(Key(k, c));
    return c;
  }

  Anchor AnchorOf(const Node& n) const {
    OnlyKeys(n, {"position", "rotation", "rotation_deg", "scale"}, "anchor");
    Anchor a;
    if (const Node* x = n.Find("position")) a.position = Vec3(*x, "anchor.position");
    if (n.Find("rotation") && n.Find("rotation_deg")) Fail(n, "anchor: give rotation or rotation_deg, not both");
    if (const Node* x = n.Find("rotation")) {
      const auto q = Numbers(*x, "anchor.rotation (x, y, z, w)", 4);
      Eigen::Quaterniond r(q[3], q[0], q[1], q[2]);
      if (r.norm() < 1e-9) Fail(*x, "anchor.rotation has zero length");
      a.rotation = r.normalized();
    }
    if (const Node* x = n.Find("rotation_deg")) {
      const Eigen::Vector3d e = Vec3(*x, "anchor.rotation_deg") * (M_PI / 180);
      a.rotation = Eigen::AngleAxisd(e.x(), Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(e.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(e.z(), Eigen::Vector3d::UnitZ());
    }
    if (const Node* x = n.Find("scale")) {
      a.scale = Number(*x, "anchor.scale");
      if (!(a.scale > 0)) Fail(*x, "anchor.scale must be positive");
    }
    return a;
  }

  KeySpec Key(const Node& n, const CharacterSpec& c) const {
    OnlyKeys(n, {"viewpoint", "azimuth", "elevation", "clip", "generate", "pose"}, "a key");
    KeySpec k;
    k.line = n.line;
    const Node* vp = n.Find("viewpoint");
    const Node* az = n.Find("azimuth");
    const Node* el = n.Find("elevation");
    if (vp && (az || el)) Fail(n, "a key gives either viewpoint or azimuth/elevation, not both");
    if (vp) {
      const Eigen::Vector3d v = Vec3(*vp, "viewpoint");
      if (!(v.norm() > 1e-9)) Fail(*vp, "key viewpoint has zero length");
      k.viewpoint = v.normalized();
    } else if (az || el) {
      const double a = az ? Number(*az, "azimuth") : 0.0;
      const double e = el ? Number(*el, "elevation") : 0.0;
      if (std::abs(e) > 90) Fail(el ? *el : n, "elevation must be within [-90, 90] degrees");
      k.viewpoint = DirectionFromAzimuthElevation(a, e, c.forward, c.up);
    } else {
      Fail(n, "a key needs 'viewpoint: [x, y, z]' or 'azimuth: <deg>'");
    }
    const int sources = (n.Find("clip") ? 1 : 0) + (n.Find("generate") ? 1 : 0) + (n.Find("pose") ? 1 : 0);
    if (sources != 1) Fail(n, "a key needs exactly one of 'clip: <name>', 'generate: lookat', 'pose: rest|<clip>@<seconds>'");
    if (const Node* x = n.Find("clip")) {
      k.source = KeySpec::Source::kClip;
      k.clip = String(*x, "clip");
    } else if (const Node* x = n.Find("generate")) {
      if (String(*x, "generate") != "lookat") Fail(*x, "generate: only 'lookat' is known");
      k.source = KeySpec::Source::kLookAt;
    } else {
      const Node& p = *n.Find("pose");
      const std::string s = String(p, "pose");
      if (s == "rest") {
        k.source = KeySpec::Source::kRestPose;
      } else {
        const auto at = s.rfind('@');
        if (at == std::string::npos || at == 0) Fail(p, "pose: expected 'rest' or '<clip>@<seconds>'");
        k.source = KeySpec::Source::kStaticPose;
        k.clip = s.substr(0, at);
        Node t = p;
        t.scalar = s.substr(at + 1);
        k.pose_time = Number(t, "pose time");
        if (k.pose_time < 0) Fail(p, "pose time must not be negative");
      }
    }
    return k;
  }

  Scene Read(const Node& root, const fs::path& file) const {
    OnlyKeys(root, {"characters"}, "the scene");
    const Node* chars = root.Find("characters");
    if (!chars || !chars->IsSequence() || chars->items.empty())
      throw Error(file_ + ": a scene needs a non-empty 'characters:' list");
    Scene s;
    s.file = file;
    const fs::path base = file.has_parent_path() ? file.parent_path() : fs::path(".");
    for (const Node& c : chars->items) s.characters.push_back(Character(c, base));
    return s;
  }

 private:
  std::string file_;
};

std::string ClipList(const Character& c) {
  std::string s;
  for (const Clip& clip : c.clips) s += (s.empty() ? "" : ", ") + clip.name;
  return s.empty() ? "none" : s;
}

}  // namespace

Eigen::Matrix4d CharacterSpec::ModelToMap() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = anchor.rotation.normalized().toRotationMatrix() * (anchor.scale * scale);
  m.block<3, 1>(0, 3) = anchor.position;
  return m;
}

Eigen::Vector3d CharacterSpec::ViewpointFromCamera(const Eigen::Vector3d& camera_center_map) const {
  const Eigen::Vector3d d = anchor.rotation.normalized().conjugate() * (camera_center_map - anchor.position);
  const double n = d.norm();
  return n > 1e-12 ? Eigen::Vector3d(d / n) : Eigen::Vector3d::Zero();
}

Scene ParseScene(const std::string& text, const fs::path& file) {
  const Node root = yaml::Parse(text, file.string());
  return SceneReader(file.string()).Read(root, file);
}

Scene LoadScene(const fs::path& path) {
  const Node root = yaml::ParseFile(path);  // errors name the file
  return SceneReader(path.string()).Read(root, path);
}

Eigen::Vector3d ParseViewpoint(const std::string& text, const std::string& what) {
  std::string t = text;
  for (char& c : t)
    if (c == ',') c = ' ';
  std::istringstream in(t);
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    std::string word;
    std::size_t used = 0;
    bool ok = static_cast<bool>(in >> word);
    if (ok) {
      try {
        v[i] = std::stod(word, &used);
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok || used != word.size() || !std::isfinite(v[i]))
      throw Error(what + ": expected three numbers \"x,y,z\", got \"" + text + "\"");
  }
  std::string extra;
  if (in >> extra) throw Error(what + ": more than three numbers in \"" + text + "\"");
  // Scaled by its largest component first: the norm of (1e308, 1e308, 1e308) overflows to
  // infinity and normalizing by it gave (0, 0, 0).
  const double largest = v.cwiseAbs().maxCoeff();
  if (!(largest > 1e-12)) throw Error(what + ": zero-length viewpoint \"" + text + "\" has no direction");
  return (v / largest).normalized();
}

AnimatedCharacter::AnimatedCharacter(const CharacterSpec& spec)
    : AnimatedCharacter(std::make_shared<const Character>(LoadCharacter(spec.asset)), spec) {}

AnimatedCharacter::AnimatedCharacter(std::shared_ptr<const Character> character, const CharacterSpec& spec)
    : character_(std::move(character)), spec_(spec) {
  const std::string where = spec_.where.empty() ? spec_.asset.string() : spec_.where;
  ViewAdaptiveOptions options;
  options.weights = spec_.weights;
  options.blend = spec_.blend;
  options.dib = spec_.dib;
  options.phase = spec_.phase;
  options.nlerp_sampling = spec_.nlerp_sampling;
  std::vector<ViewAdaptiveKey> keys = BuildKeys();
  try {
    blend_ = std::make_shared<ViewAdaptiveBlend>(shared_skeleton(), std::move(keys), options);
  } catch (const Error& e) {
    throw Error(where + ": " + e.what());
  }
  const Skeleton& sk = character_->skeleton;
  blended_ = LocalPose::Rest(sk);
  model_.assign(sk.size(), Eigen::Matrix4d::Identity());
  skin_.assign(sk.size(), Eigen::Matrix4f::Identity());
  skin_dq_.assign(sk.size(), DualQuatf());
}

std::vector<ViewAdaptiveKey> AnimatedCharacter::BuildKeys() {
  const Character& c = *character_;
  const Skeleton& sk = c.skeleton;
  const std::string where = spec_.where.empty() ? spec_.asset.string() : spec_.where;
  auto key_where = [&](const KeySpec& k) {
    return k.line > 0 && !spec_.where.empty() ? spec_.where.substr(0, spec_.where.rfind(':')) + ":" + std::to_string(k.line)
                                              : where;
  };
  auto find_clip = [&](const KeySpec& k, const std::string& name) -> const Clip& {
    const Clip* clip = c.FindClip(name);
    if (!clip)
      throw Error(key_where(k) + ": clip '" + name + "' does not exist in " + c.source + " (clips: " + ClipList(c) + ")");
    return *clip;
  };
  const bool any_lookat = std::any_of(spec_.keys.begin(), spec_.keys.end(),
                                      [](const KeySpec& k) { return k.source == KeySpec::Source::kLookAt; });
  const Clip* lookat_base = nullptr;
  if (any_lookat) {
    try {
      chain_ = MakeLookAtChain(sk, spec_.lookat.chain, spec_.lookat.limits_deg, spec_.forward, spec_.up);
    } catch (const Error& e) {
      throw Error(where + ": " + e.what());
    }
    if (spec_.lookat.base_clip == "rest" && !c.FindClip("rest")) {
      lookat_base = nullptr;  // a static look from the rest pose
    } else if (!spec_.lookat.base_clip.empty()) {
      lookat_base = c.FindClip(spec_.lookat.base_clip);
      if (!lookat_base)
        throw Error(where + ": lookat.base_clip '" + spec_.lookat.base_clip + "' does not exist in " + c.source +
                    " (clips: " + ClipList(c) + ")");
    } else if (!c.clips.empty()) {
      lookat_base = &c.clips.front();
    }
  }
  std::vector<std::shared_ptr<const Clip>> key_clips;
  for (const KeySpec& k : spec_.keys) {
    switch (k.source) {
      case KeySpec::Source::kClip:
        // Alias into the character: no copy.
        key_clips.push_back(std::shared_ptr<const Clip>(character_, &find_clip(k, k.clip)));
        break;
      case KeySpec::Source::kLookAt:
        key_clips.push_back(std::make_shared<const Clip>(GenerateLookAtClip(sk, lookat_base, chain_, k.viewpoint)));
        break;
      case KeySpec::Source::kRestPose: {
        Clip rest;
        rest.name = "rest";
        rest.tracks.resize(sk.size());
        key_clips.push_back(std::make_shared<const Clip>(std::move(rest)));
        break;
      }
      case KeySpec::Source::kStaticPose: {
        const Clip& from = find_clip(k, k.clip);
        LocalPose pose(sk.size());
        MustRun(SamplingJob{&sk, &from, k.pose_time, false, &pose}, "static pose key");
        Clip still;
        still.name = k.clip + "@" + std::to_string(k.pose_time);
        still.tracks.resize(sk.size());
        for (int j = 0; j < sk.size(); ++j) {
          still.tracks[j].rotation.push_back({0.0, pose.rigid[j].Rotation()});
          still.tracks[j].translation.push_back({0.0, pose.rigid[j].Translation()});
          still.tracks[j].scale.push_back({0.0, pose.scale[j]});
        }
        key_clips.push_back(std::make_shared<const Clip>(std::move(still)));
        break;
      }
    }
  }
  std::vector<ViewAdaptiveKey> keys;
  for (std::size_t k = 0; k < spec_.keys.size(); ++k) keys.push_back({spec_.keys[k].viewpoint, key_clips[k]});
  return keys;
}

const FrameOutput& AnimatedCharacter::Update(const Eigen::Vector3d& viewpoint, double time_seconds) {
  const Skeleton& sk = character_->skeleton;
  FrameInputs inputs;
  inputs.viewpoint = viewpoint;
  if (!blend_->Sample(time_seconds, inputs, blended_)) throw Error(spec_.where + ": view-adaptive blend: key clips and skeleton disagree");
  MustRun(LocalToModelJob{&sk, &blended_, model_}, "local to model");
  MustRun(SkinningMatricesJob{&sk, model_, skin_, skin_dq_}, "skinning matrices");
  out_.weights = blend_->weights();
  out_.converged = blend_->converged();
  out_.max_iterations = blend_->max_iterations();
  out_.model = model_;
  out_.skinning_matrices = skin_;
  out_.skinning_dual_quats = skin_dq_;
  return out_;
}

}  // namespace arview::anim
