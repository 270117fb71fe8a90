#include "anim_authoring/scene_reader.h"

#include "base/library_errors.h"

#include "anim_authoring/yaml.h"
#include "anim/view_sphere.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstdio>
#include <cmath>
#include <set>
#include <sstream>

namespace arview::authoring {

namespace fs = std::filesystem;
using Node = yaml::Node;

CharacterSpec SceneReader::Character(const Node& n, const fs::path& base_dir) const {
  OnlyKeys(n, {"name", "asset", "scale", "anchor", "forward", "up", "weights", "blend", "phase", "sampling", "lookat", "gesture",
               "keys", "scopes", "idle", "schedule", "gaze", "voice", "lines"},
           "a character");
  CharacterSpec c;
  c.where = file_ + ":" + std::to_string(n.line);
  if (const Node* x = n.Find("name")) c.name = String(*x, "name");
  const Node* asset = n.Find("asset");
  if (!asset) Fail(n, "a character needs 'asset: <file>'");
  fs::path a = String(*asset, "asset");
  if (IsBuiltinAsset(a)) {  // generated in code, not a file: no path to resolve
    c.asset = a;
    if (c.name.empty()) c.name = a.string().substr(std::string(kBuiltinAssetPrefix).size());
  } else {
    if (a.is_relative()) a = base_dir / a;
    c.asset = fs::absolute(a).lexically_normal();
  }
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
      c.weights.mode = Choice<anim::WeightingMode>(*y, "weights.mode",
                                             {{"inverse-distance", anim::WeightingMode::kInverseDistance},
                                              {"local", anim::WeightingMode::kLocalSupport}});
    if (const Node* y = x->Find("distance"))
      c.weights.distance = Choice<anim::DistanceKind>(*y, "weights.distance",
                                                {{"geodesic", anim::DistanceKind::kGeodesic}, {"chordal", anim::DistanceKind::kChordal}});
    if (const Node* y = x->Find("alpha")) {
      c.weights.alpha = Number(*y, "weights.alpha");
      if (!(c.weights.alpha > 0)) Fail(*y, "weights.alpha must be positive");
    }
  }
  if (const Node* x = n.Find("blend")) {
    OnlyKeys(*x, {"method", "precision", "max_iterations"}, "blend");
    if (const Node* y = x->Find("method"))
      c.blend = Choice<anim::BlendMethod>(*y, "blend.method", {{"dlb", anim::BlendMethod::kDlb}, {"dib", anim::BlendMethod::kDib}});
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
    c.phase = Choice<anim::PhaseMode>(*x, "phase", {{"shared", anim::PhaseMode::kShared}, {"independent", anim::PhaseMode::kIndependent}});
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
  if (const Node* x = n.Find("gesture")) c.gesture = GestureOf(*x);
  const Node* keys = n.Find("keys");
  if (!keys || !keys->IsSequence() || keys->items.empty()) Fail(n, "a character needs a non-empty 'keys:' list");
  for (const Node& k : keys->items) c.keys.push_back(Key(k, c));
  if (const Node* x = n.Find("scopes")) c.scopes = Scopes(*x);
  if (const Node* x = n.Find("idle")) c.idle = Idle(*x, base_dir);
  if (const Node* x = n.Find("schedule")) c.schedule = ScheduleOf(*x);
  if (const Node* x = n.Find("gaze")) c.gaze = GazeOf(*x);
  if (const Node* x = n.Find("voice")) {
    c.voice = String(*x, "voice");
    c.voice_line = x->line;
  }
  if (const Node* x = n.Find("lines")) c.lines = Lines(*x);
  return c;
}

std::vector<LineSpec> SceneReader::Lines(const Node& n) const {
  if (!n.IsSequence()) Fail(n, "lines: expected a list of {when: ..., say: ...}");
  if (n.items.size() > kMaxLinesPerCharacter)
    Fail(n, "lines: " + std::to_string(n.items.size()) + " lines, at most " + std::to_string(kMaxLinesPerCharacter));
  std::vector<LineSpec> lines;
  for (const Node& item : n.items) lines.push_back(Line(item));
  return lines;
}

LineSpec SceneReader::Line(const Node& n) const {
  OnlyKeys(n, {"when", "say", "near", "far"}, "a line");
  LineSpec l;
  const Node* say = n.Find("say");
  if (!say) Fail(n, "a line needs 'say: <text>'");
  l.say = String(*say, "say");
  l.line = say->line;
  const Node* when = n.Find("when");
  if (!when) Fail(n, "a line needs 'when: start | near | behind | lost | found'");
  l.when = Choice<LineCue>(*when, "when", {{"start", LineCue::kStart},
                                           {"near", LineCue::kNear},
                                           {"behind", LineCue::kBehind},
                                           {"lost", LineCue::kLost},
                                           {"found", LineCue::kFound}});
  const Node* near = n.Find("near");
  const Node* far = n.Find("far");
  if (l.when != LineCue::kNear && (near || far)) Fail(near ? *near : *far, "near and far are for 'when: near' lines");
  if (near) {
    l.near = NonNegative(*near, "near");
    l.far = l.near * 1.25 + 0.1;  // the distance triggers' default hysteresis
  }
  if (far) l.far = Number(*far, "far");
  if (!(l.far > l.near)) Fail(far ? *far : n, "far must be beyond near (hysteresis)");
  return l;
}

GazeSpec SceneReader::GazeOf(const Node& n) const {
  OnlyKeys(n, {"enabled", "mode", "blink_rate", "eye_range", "seed"}, "gaze");
  GazeSpec g;
  g.line = n.line;
  if (const Node* x = n.Find("enabled")) g.enabled = Bool(*x, "gaze.enabled");
  if (const Node* x = n.Find("mode"))
    g.options.mode = Choice<anim::GazeMode>(*x, "gaze.mode", {{"listening", anim::GazeMode::kListening},
                                                              {"talking", anim::GazeMode::kTalking},
                                                              {"rest", anim::GazeMode::kRest}});
  if (const Node* x = n.Find("blink_rate")) {
    g.options.blink_rate_per_min = Number(*x, "gaze.blink_rate");
    if (!(g.options.blink_rate_per_min > 0) || g.options.blink_rate_per_min > 100)
      Fail(*x, "gaze.blink_rate: blinks per minute, in (0, 100]");
  }
  if (const Node* x = n.Find("eye_range")) {
    OnlyKeys(*x, {"sideways", "up", "down"}, "gaze.eye_range");
    auto angle = [&](const char* key, double& out) {
      if (const Node* y = x->Find(key)) {
        out = Number(*y, std::string("gaze.eye_range.") + key);
        if (!(out > 0) || out > 60) Fail(*y, std::string("gaze.eye_range.") + key + ": degrees, in (0, 60]");
      }
    };
    angle("sideways", g.options.range.sideways_deg);
    angle("up", g.options.range.up_deg);
    angle("down", g.options.range.down_deg);
  }
  if (const Node* x = n.Find("seed")) g.options.seed = static_cast<std::uint64_t>(Integer(*x, "gaze.seed", 0, 2147483647));
  return g;
}

Anchor SceneReader::AnchorOf(const Node& n) const {
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

GestureSpec SceneReader::GestureOf(const Node& n) const {
  OnlyKeys(n, {"arm", "chain", "elbow", "shoulder_cone", "bend"}, "gesture");
  GestureSpec g;
  if (const Node* y = n.Find("arm"))
    g.side = Choice<ArmSide>(*y, "gesture.arm", {{"right", ArmSide::kRight}, {"left", ArmSide::kLeft}});
  if (const Node* y = n.Find("chain")) {
    if (!y->IsSequence() || y->items.size() != 3)
      Fail(*y, "gesture.chain: expected [upper arm, forearm, hand] joint names");
    for (const Node& j : y->items) g.chain.push_back(String(j, "gesture.chain"));
  }
  if (const Node* y = n.Find("elbow")) {
    const auto range = Numbers(*y, "gesture.elbow", 2);
    if (!(range[0] >= 0 && range[0] <= range[1] && range[1] <= 180))
      Fail(*y, "gesture.elbow: expected [min, max] bend with 0 <= min <= max <= 180 degrees");
    g.limits.elbow_min_deg = range[0];
    g.limits.elbow_max_deg = range[1];
  }
  if (const Node* y = n.Find("shoulder_cone")) {
    g.limits.shoulder_cone_deg = Number(*y, "gesture.shoulder_cone");
    if (!(g.limits.shoulder_cone_deg > 0 && g.limits.shoulder_cone_deg <= 180))
      Fail(*y, "gesture.shoulder_cone must be in (0, 180] degrees");
  }
  if (const Node* y = n.Find("bend")) {
    OnlyKeys(*y, {"point", "reach"}, "gesture.bend");
    for (const char* which : {"point", "reach"})
      if (const Node* z = y->Find(which)) {
        const double b = Number(*z, std::string("gesture.bend.") + which);
        if (!(b >= 0 && b <= 180)) Fail(*z, std::string("gesture.bend.") + which + " must be in [0, 180] degrees");
        (std::string(which) == "point" ? g.limits.point_bend_deg : g.limits.reach_bend_deg) = b;
      }
  }
  return g;
}

KeySpec SceneReader::Key(const Node& n, const CharacterSpec& c) const {
  OnlyKeys(n, {"viewpoint", "azimuth", "elevation", "clip", "generate", "gesture", "pose"}, "a key");
  KeySpec k;
  k.line = n.line;
  const Node* vp = n.Find("viewpoint");
  const Node* az = n.Find("azimuth");
  const Node* el = n.Find("elevation");
  if (vp && (az || el)) Fail(n, "a key gives either viewpoint or azimuth/elevation, not both");
  if (vp) {
    k.viewpoint = Direction(*vp, "key viewpoint");
  } else if (az || el) {
    const double a = az ? Number(*az, "azimuth") : 0.0;
    const double e = el ? Number(*el, "elevation") : 0.0;
    if (std::abs(e) > 90) Fail(el ? *el : n, "elevation must be within [-90, 90] degrees");
    k.viewpoint = anim::DirectionFromAzimuthElevation(a, e, c.forward, c.up);
  } else {
    Fail(n, "a key needs 'viewpoint: [x, y, z]' or 'azimuth: <deg>'");
  }
  // A gesture key is a generated look-at key with the arm on top: `generate: lookat` may go with it.
  const bool generated = n.Find("generate") || n.Find("gesture");
  const int sources = (n.Find("clip") ? 1 : 0) + (generated ? 1 : 0) + (n.Find("pose") ? 1 : 0);
  if (sources != 1)
    Fail(n, "a key needs exactly one of 'clip: <name>', 'generate: lookat', 'gesture: point|reach', "
            "'pose: rest|<clip>@<seconds>'");
  if (const Node* x = n.Find("clip")) {
    k.source = KeySpec::Source::kClip;
    k.clip = String(*x, "clip");
  } else if (generated) {
    if (const Node* x = n.Find("generate"))
      if (String(*x, "generate") != "lookat") Fail(*x, "generate: only 'lookat' is known (gestures: 'gesture: point|reach')");
    k.source = KeySpec::Source::kLookAt;
    if (const Node* x = n.Find("gesture"))
      k.gesture = Choice<Gesture>(*x, "gesture", {{"point", Gesture::kPoint}, {"reach", Gesture::kReach}});
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

Scene SceneReader::Read(const Node& root, const fs::path& file) const {
  OnlyKeys(root, {"characters"}, "the scene");
  const Node* chars = root.Find("characters");
  if (!chars || !chars->IsSequence() || chars->items.empty())
    throw anim::Error(file_ + ": a scene needs a non-empty 'characters:' list");
  Scene s;
  s.file = file;
  const fs::path base = file.has_parent_path() ? file.parent_path() : fs::path(".");
  for (const Node& c : chars->items) s.characters.push_back(Character(c, base));
  return s;
}


Scene ParseScene(const std::string& text, const fs::path& file) {
  const Node root = yaml::Parse(text, file.string());
  return SceneReader(file.string()).Read(root, file);
}

namespace {

Scene LoadSceneFile(const fs::path& path) {
  const Node root = yaml::ParseFile(path);  // errors name the file
  return SceneReader(path.string()).Read(root, path);
}

}  // namespace

Scene LoadScene(const fs::path& path) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<anim::Error>(path.string(), [&] { return LoadSceneFile(path); });
}

Eigen::Vector3d ParseViewpoint(const std::string& text, const std::string& what) {
  std::string t = text;
  for (char& c : t)
    if (c == ',') c = ' ';
  std::istringstream in(t);
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    std::string word;
    if (!(in >> word)) throw anim::Error(what + ": expected three numbers \"x,y,z\", got \"" + text + "\"");
    // strtod, not stod: stod refuses a denormal such as 5e-324 as out of range, which was then
    // reported as "expected three numbers"; the length check below says what is wrong with it.
    errno = 0;
    char* end = nullptr;
    v[i] = std::strtod(word.c_str(), &end);
    if (end != word.c_str() + word.size() || !std::isfinite(v[i]) || (errno == ERANGE && std::abs(v[i]) > 1)) {
      throw anim::Error(what + ": '" + word + "' in \"" + text + "\" is not a finite number (expected three numbers \"x,y,z\")");
    }
  }
  std::string extra;
  if (in >> extra) throw anim::Error(what + ": more than three numbers in \"" + text + "\"");
  try {
    return anim::UnitDirection(v);
  } catch (const anim::Error& e) {
    throw anim::Error(what + ": the viewpoint " + e.what());
  }
}

anim::Placement CharacterSpec::placement() const { return {anchor, scale, forward, up}; }

std::string KeySourceLabel(const KeySpec& key) {
  switch (key.source) {
    case KeySpec::Source::kClip: return key.clip;
    case KeySpec::Source::kLookAt: return "lookat";
    case KeySpec::Source::kRestPose: return "rest";
    case KeySpec::Source::kStaticPose: {
      char t[32];
      std::snprintf(t, sizeof t, "@%g", key.pose_time);
      return key.clip + t;
    }
  }
  return "?";
}

}  // namespace arview::authoring
