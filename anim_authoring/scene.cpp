#include "anim_authoring/scene.h"

#include "anim_authoring/balance.h"
#include "anim_authoring/idle_learning.h"
#include "anim_authoring/yaml.h"

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
    OnlyKeys(n, {"name", "asset", "scale", "anchor", "forward", "up", "weights", "blend", "phase", "sampling", "lookat", "gesture",
                 "keys", "scopes", "idle", "schedule"},
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
    if (const Node* x = n.Find("gesture")) c.gesture = GestureOf(*x);
    const Node* keys = n.Find("keys");
    if (!keys || !keys->IsSequence() || keys->items.empty()) Fail(n, "a character needs a non-empty 'keys:' list");
    for (const Node& k : keys->items) c.keys.push_back(Key(k, c));
    if (const Node* x = n.Find("scopes")) c.scopes = Scopes(*x);
    if (const Node* x = n.Find("idle")) c.idle = Idle(*x, base_dir);
    if (const Node* x = n.Find("schedule")) c.schedule = ScheduleOf(*x);
    return c;
  }

  bool Bool(const Node& n, const std::string& what) const {
    return Choice<bool>(n, what, {{"true", true}, {"false", false}});
  }

  int Integer(const Node& n, const std::string& what, int lo, int hi) const {
    const double x = Number(n, what);
    if (x != std::floor(x) || x < lo || x > hi)
      Fail(n, what + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
    return static_cast<int>(x);
  }

  double NonNegative(const Node& n, const std::string& what) const {
    const double x = Number(n, what);
    if (x < 0) Fail(n, what + " must not be negative");
    return x;
  }

  ScopeTable Scopes(const Node& n) const {
    if (!n.IsMapping()) Fail(n, "scopes must be a mapping of name: [joints]");
    ScopeTable table;
    for (const auto& [name, v] : n.entries) {
      ScopeSpec spec;
      const Node* joints = &v;
      if (v.IsMapping()) {
        OnlyKeys(v, {"joints", "descendants"}, "scope '" + name + "'");
        joints = v.Find("joints");
        if (!joints) Fail(v, "scope '" + name + "' needs 'joints: [names]'");
        if (const Node* d = v.Find("descendants")) spec.descendants = Bool(*d, "descendants");
      }
      if (!joints->IsSequence() || joints->items.empty()) Fail(*joints, "scope '" + name + "': expected a list of joint names");
      for (const Node& j : joints->items) spec.joints.push_back(String(j, "scope joint"));
      table[name] = spec;
    }
    return table;
  }

  IdleSpec Idle(const Node& n, const fs::path& base_dir) const {
    OnlyKeys(n, {"motion", "clips", "joint_map", "seed", "components", "balance"}, "idle");
    IdleSpec idle;
    idle.given = true;
    idle.line = n.line;
    if (const Node* x = n.Find("motion")) {
      if (!x->IsSequence()) Fail(*x, "idle.motion: expected a list of motion files");
      for (const Node& f : x->items) {
        fs::path p = String(f, "idle.motion");
        if (p.is_relative()) p = base_dir / p;
        idle.motion.push_back(fs::absolute(p).lexically_normal());
      }
    }
    if (const Node* x = n.Find("clips")) {
      if (!x->IsSequence()) Fail(*x, "idle.clips: expected a list of clip names");
      for (const Node& c : x->items) idle.clips.push_back(String(c, "idle.clips"));
    }
    if (idle.motion.empty() && idle.clips.empty()) Fail(n, "idle needs 'motion: [files]' and/or 'clips: [names]' to learn from");
    if (const Node* x = n.Find("joint_map")) {
      if (!x->IsMapping()) Fail(*x, "idle.joint_map: expected data_joint: character_joint entries");
      for (const auto& [from, to] : x->entries) idle.joint_map[from] = String(to, "idle.joint_map");
    }
    if (const Node* x = n.Find("seed")) idle.seed = static_cast<std::uint64_t>(Integer(*x, "idle.seed", 0, 2147483647));
    if (const Node* x = n.Find("components")) idle.components = Integer(*x, "idle.components", 1, 64);
    if (const Node* x = n.Find("balance")) idle.balance = Balance(*x, base_dir, idle.components);
    return idle;
  }

  BalanceSpec Balance(const Node& n, const fs::path& base_dir, int idle_components) const {
    OnlyKeys(n, {"motion", "clip", "seed", "components"}, "idle.balance");
    BalanceSpec b;
    b.given = true;
    b.line = n.line;
    const Node* motion = n.Find("motion");
    const Node* clip = n.Find("clip");
    if ((motion != nullptr) == (clip != nullptr))
      Fail(n, "idle.balance needs exactly one of 'motion: <file>' (a recording of a person standing) or 'clip: <name>' "
              "(a clip of the character)");
    if (motion) {
      fs::path p = String(*motion, "idle.balance.motion");
      if (p.is_relative()) p = base_dir / p;
      b.motion = fs::absolute(p).lexically_normal();
    }
    if (clip) b.clip = String(*clip, "idle.balance.clip");
    if (const Node* x = n.Find("seed")) b.seed = static_cast<std::uint64_t>(Integer(*x, "idle.balance.seed", 0, 2147483647));
    if (const Node* x = n.Find("components")) {
      b.components = Integer(*x, "idle.balance.components", 1, 64);
      if (b.components > idle_components)
        Fail(*x, "idle.balance.components: " + std::to_string(b.components) + " is more than the idle model's " +
                     std::to_string(idle_components) + " (idle.components)");
    } else {
      b.components = std::min(b.components, idle_components);
    }
    return b;
  }

  Curve CurveOf(const Node& n, const std::string& what) const {
    OnlyKeys(n, {"shape", "in", "out", "attack", "decay", "sustain", "release", "peak", "seconds"}, what);
    Curve c;
    if (const Node* x = n.Find("shape"))
      c.shape = Choice<Curve::Shape>(*x, what + ".shape",
                                     {{"constant", Curve::Shape::kConstant},
                                      {"linear-fade", Curve::Shape::kLinearFade},
                                      {"cosine-fade", Curve::Shape::kCosineFade},
                                      {"adsr", Curve::Shape::kAdsr},
                                      {"cosine-adsr", Curve::Shape::kCosineAdsr}});
    if (const Node* x = n.Find("in")) c.fade_in = NonNegative(*x, what + ".in");
    if (const Node* x = n.Find("out")) c.fade_out = NonNegative(*x, what + ".out");
    if (const Node* x = n.Find("attack")) c.attack = NonNegative(*x, what + ".attack");
    if (const Node* x = n.Find("decay")) c.decay = NonNegative(*x, what + ".decay");
    if (const Node* x = n.Find("release")) c.release = NonNegative(*x, what + ".release");
    if (const Node* x = n.Find("sustain")) c.sustain = NonNegative(*x, what + ".sustain");
    if (const Node* x = n.Find("peak")) c.peak = NonNegative(*x, what + ".peak");
    if (const Node* x = n.Find("seconds")) c.in_seconds = Bool(*x, what + ".seconds");
    if (c.sustain > 1) Fail(n, what + ".sustain is a fraction of the peak, at most 1");
    return c;
  }

  std::vector<Curve> Curves(const Node& n, const std::string& what) const {
    std::vector<Curve> out;
    if (n.IsSequence())
      for (const Node& c : n.items) out.push_back(CurveOf(c, what));
    else
      out.push_back(CurveOf(n, what));
    return out;
  }

  // A mask weight: a number (rotation and translation alike) or {rotation: r, translation: t}.
  std::pair<double, double> MaskWeight(const Node& n, const std::string& what) const {
    if (n.IsMapping()) {
      OnlyKeys(n, {"rotation", "translation"}, what);
      const Node* r = n.Find("rotation");
      const Node* t = n.Find("translation");
      return {r ? NonNegative(*r, what + ".rotation") : 1.0, t ? NonNegative(*t, what + ".translation") : 1.0};
    }
    const double w = NonNegative(n, what);
    return {w, w};
  }

  MaskSpec MaskOf(const Node& n) const {
    if (!n.IsMapping()) Fail(n, "mask: expected {default: w, <scope>: w, ...}");
    MaskSpec m;
    m.line = n.line;
    for (const auto& [key, v] : n.entries) {
      const auto [r, t] = MaskWeight(v, "mask." + key);
      if (key == "default") {
        m.default_rotation = r;
        m.default_translation = t;
      } else {
        m.scopes.push_back({key, r, t});
      }
    }
    return m;
  }

  ObjectSpec ObjectOf(const Node& n) const {
    OnlyKeys(n, {"clip", "pose", "view_adaptive", "idle", "schedule", "window", "stretch", "loop", "mirror", "transform"},
             "an object");
    ObjectSpec o;
    o.line = n.line;
    const int kinds = (n.Find("clip") ? 1 : 0) + (n.Find("pose") ? 1 : 0) + (n.Find("view_adaptive") ? 1 : 0) +
                      (n.Find("idle") ? 1 : 0) + (n.Find("schedule") ? 1 : 0);
    if (kinds != 1)
      Fail(n, "an object needs exactly one of 'clip: <name>', 'pose: rest|<clip>@<s>', 'view_adaptive: true', 'idle: true', "
              "'schedule: {actions: [...]}'");
    if (const Node* x = n.Find("clip")) {
      o.kind = ObjectSpec::Kind::kClip;
      o.clip = String(*x, "clip");
    } else if (const Node* x = n.Find("pose")) {
      o.kind = ObjectSpec::Kind::kPose;
      const std::string p = String(*x, "pose");
      if (p != "rest") {
        const auto at = p.rfind('@');
        if (at == std::string::npos || at == 0) Fail(*x, "pose: expected 'rest' or '<clip>@<seconds>'");
        o.clip = p.substr(0, at);
        Node t = *x;
        t.scalar = p.substr(at + 1);
        o.pose_time = NonNegative(t, "pose time");
      }
    } else if (const Node* x = n.Find("view_adaptive")) {
      if (!Bool(*x, "view_adaptive")) Fail(*x, "view_adaptive: only 'true' makes an object");
      o.kind = ObjectSpec::Kind::kViewAdaptive;
    } else if (const Node* x = n.Find("idle")) {
      if (!Bool(*x, "idle")) Fail(*x, "idle: only 'true' makes an object");
      o.kind = ObjectSpec::Kind::kIdle;
    } else {
      const Node& sched = *n.Find("schedule");
      OnlyKeys(sched, {"actions"}, "a nested schedule");
      const Node* actions = sched.Find("actions");
      if (!actions || !actions->IsSequence() || actions->items.empty()) Fail(sched, "a nested schedule needs 'actions: [...]'");
      o.kind = ObjectSpec::Kind::kSchedule;
      for (const Node& a : actions->items) o.actions.push_back(ActionOf(a));
    }
    if (const Node* x = n.Find("window")) {
      const auto w = Numbers(*x, "window", 2);
      if (!(w[0] >= 0) || !(w[1] > w[0])) Fail(*x, "window: needs [from, to] with 0 <= from < to (seconds)");
      o.has_window = true;
      o.window_from = w[0];
      o.window_to = w[1];
    }
    if (const Node* x = n.Find("stretch")) {
      o.stretch = Number(*x, "stretch");
      if (!(o.stretch > 0)) Fail(*x, "stretch: the new length must be positive (seconds)");
    }
    if (const Node* x = n.Find("loop")) {
      if (x->IsScalar() && (x->scalar == "true" || x->scalar == "false")) o.loop = x->scalar == "true" ? 0 : -1;
      else o.loop = Integer(*x, "loop (true or a count)", 1, 1000000);
    }
    if (const Node* x = n.Find("mirror")) o.mirror = Bool(*x, "mirror");
    if (const Node* x = n.Find("transform")) {
      o.has_transform = true;
      o.transform = AnchorOf(*x);
    }
    return o;
  }

  ActionSpec ActionOf(const Node& n) const {
    OnlyKeys(n, {"name", "object", "start", "keep_rendering", "layer", "weight", "curve", "curves", "scaling", "mask", "masks",
                 "trigger", "distance"},
             "an action");
    ActionSpec a;
    a.line = n.line;
    if (const Node* x = n.Find("name")) a.name = String(*x, "name");
    const Node* object = n.Find("object");
    if (!object) Fail(n, "an action needs 'object: {...}'");
    a.object = ObjectOf(*object);
    if (const Node* x = n.Find("start")) a.start = Number(*x, "start");
    if (const Node* x = n.Find("keep_rendering")) a.keep_rendering = Bool(*x, "keep_rendering");
    if (const Node* x = n.Find("layer")) a.layer = Integer(*x, "layer", 0, 15);
    if (const Node* x = n.Find("weight")) a.weight = NonNegative(*x, "weight");
    if (n.Find("curve") && n.Find("curves")) Fail(n, "give 'curve' or 'curves', not both");
    if (const Node* x = n.Find("curve")) a.curves = Curves(*x, "curve");
    if (const Node* x = n.Find("curves")) a.curves = Curves(*x, "curves");
    if (const Node* x = n.Find("scaling")) a.scalings = Curves(*x, "scaling");
    if (n.Find("mask") && n.Find("masks")) Fail(n, "give 'mask' or 'masks', not both");
    if (const Node* x = n.Find("mask")) a.masks.push_back(MaskOf(*x));
    if (const Node* x = n.Find("masks")) {
      if (!x->IsSequence()) Fail(*x, "masks: expected a list of masks");
      for (const Node& m : x->items) a.masks.push_back(MaskOf(m));
    }
    if (const Node* x = n.Find("trigger")) {
      OnlyKeys(*x, {"near", "far"}, "trigger");
      const Node* near = x->Find("near");
      if (!near) Fail(*x, "trigger needs 'near: <metres>'");
      a.has_trigger = true;
      a.trigger_near = NonNegative(*near, "trigger.near");
      a.trigger_far = a.trigger_near * 1.25 + 0.1;  // default hysteresis band
      if (const Node* far = x->Find("far")) a.trigger_far = Number(*far, "trigger.far");
      if (!(a.trigger_far > a.trigger_near)) Fail(*x, "trigger: far must be beyond near (hysteresis)");
    }
    if (const Node* x = n.Find("distance")) {
      if (!x->IsSequence() || x->items.empty()) Fail(*x, "distance: expected [[metres, weight], ...]");
      for (const Node& p : x->items) {
        const auto v = Numbers(p, "distance point [metres, weight]", 2);
        if (v[1] < 0) Fail(p, "distance: weights must not be negative");
        if (!a.distance_weight.empty() && !(v[0] > a.distance_weight.back().first))
          Fail(p, "distance: distances must increase");
        a.distance_weight.emplace_back(v[0], v[1]);
      }
    }
    return a;
  }

  ScheduleSpec ScheduleOf(const Node& n) const {
    OnlyKeys(n, {"actions", "rest_threshold", "tracking_loss"}, "schedule");
    ScheduleSpec s;
    s.given = true;
    const Node* actions = n.Find("actions");
    if (!actions || !actions->IsSequence() || actions->items.empty()) Fail(n, "schedule needs a non-empty 'actions:' list");
    for (const Node& a : actions->items) s.actions.push_back(ActionOf(a));
    if (const Node* x = n.Find("rest_threshold")) s.rest_threshold = NonNegative(*x, "rest_threshold");
    if (const Node* x = n.Find("tracking_loss")) {
      OnlyKeys(*x, {"hold", "fade", "action"}, "tracking_loss");
      if (const Node* y = x->Find("hold")) s.hold_seconds = NonNegative(*y, "tracking_loss.hold");
      if (const Node* y = x->Find("fade")) s.fade_seconds = NonNegative(*y, "tracking_loss.fade");
      if (const Node* y = x->Find("action")) s.view_action = String(*y, "tracking_loss.action");
    }
    std::set<std::string> names;
    for (const ActionSpec& a : s.actions)
      if (!a.name.empty() && !names.insert(a.name).second) Fail(*actions, "two actions named '" + a.name + "'");
    return s;
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

  GestureSpec GestureOf(const Node& n) const {
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

  KeySpec Key(const Node& n, const CharacterSpec& c) const {
    OnlyKeys(n, {"viewpoint", "azimuth", "elevation", "clip", "generate", "gesture", "pose"}, "a key");
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
  const bool any_gesture = std::any_of(spec_.keys.begin(), spec_.keys.end(),
                                       [](const KeySpec& k) { return k.gesture != Gesture::kNone; });
  if (any_gesture) {
    try {
      arm_ = MakeArmChain(sk, spec_.gesture.chain, spec_.gesture.side, spec_.gesture.limits, spec_.forward, spec_.up);
    } catch (const Error& e) {
      throw Error(where + ": " + e.what());
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
        if (k.gesture != Gesture::kNone)
          key_clips.push_back(
              std::make_shared<const Clip>(GenerateGestureClip(sk, lookat_base, &chain_, arm_, k.gesture, k.viewpoint)));
        else
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

namespace {

class AnimatorBuilder {
 public:
  AnimatorBuilder(const AnimatedCharacter& ch, const AnimatorOverrides& o)
      : ch_(ch), spec_(ch.spec()), sk_(ch.shared_skeleton()), overrides_(o) {
    file_ = spec_.where.substr(0, spec_.where.rfind(':'));
    if (file_.empty()) file_ = spec_.asset.string();
  }

  // After Build: notes for the user about layers built without what the scene asked for.
  const std::vector<std::string>& notes() const { return notes_; }

  std::unique_ptr<Animator> Build() {
    FrameBlenderOptions blender;
    blender.method = spec_.blend;
    blender.dib = spec_.dib;
    blender.rest_threshold = spec_.schedule.rest_threshold;
    std::vector<ActionSpec> actions = spec_.schedule.given ? spec_.schedule.actions : DefaultActions();
    int triggers = 0;
    for (const ActionSpec& a : actions) triggers += a.has_trigger;
    auto schedule = std::make_shared<Schedule>(sk_, blender, std::min<int>(60, static_cast<int>(actions.size()) + 4 * triggers + 4));
    AnimatorOptions options;
    options.view_action = spec_.schedule.view_action;
    options.hold_seconds = overrides_.hold_seconds.value_or(spec_.schedule.hold_seconds);
    options.fade_seconds = overrides_.fade_seconds.value_or(spec_.schedule.fade_seconds);
    for (std::size_t i = 0; i < actions.size(); ++i) {
      ActionSpec a = actions[i];
      if (a.name.empty()) a.name = "action" + std::to_string(i + 1);
      Action action = MakeAction(a);
      if (a.has_trigger) {
        options.triggers.push_back({a.trigger_near, a.trigger_far, std::move(action)});
        continue;
      }
      try {
        schedule->Add(std::move(action));
      } catch (const Error& e) {
        throw Error(At(a.line) + e.what());
      }
      if (!a.distance_weight.empty()) options.distance_weights.push_back({a.name, a.distance_weight});
    }
    if (!options.view_action.empty() && schedule->FindByName(options.view_action) < 0) options.view_action.clear();
    try {
      return std::make_unique<Animator>(sk_, schedule, std::move(options), ch_.view_adaptive());
    } catch (const Error& e) {
      throw Error(spec_.where + ": " + e.what());
    }
  }

 private:
  std::string At(int line) const { return file_ + ":" + std::to_string(line) + ": "; }

  std::vector<ActionSpec> DefaultActions() const {
    ActionSpec idle;
    idle.name = "idle";
    idle.keep_rendering = true;
    idle.line = 0;
    const Character& c = ch_.character();
    std::string clip = overrides_.idle_clip;
    if (clip.empty() && spec_.lookat.base_clip != "rest") {
      clip = spec_.lookat.base_clip;
      if (clip.empty() && !c.clips.empty()) clip = c.clips.front().name;
    }
    if (spec_.idle.given && overrides_.idle_clip.empty()) {
      idle.object.kind = ObjectSpec::Kind::kIdle;
    } else if (!clip.empty()) {
      idle.object.kind = ObjectSpec::Kind::kClip;
      idle.object.clip = clip;
      idle.object.loop = 0;
    } else {
      idle.object.kind = ObjectSpec::Kind::kPose;  // the rest pose
    }
    ActionSpec view;
    view.name = "view";
    view.keep_rendering = true;
    view.layer = 1;
    view.object.kind = ObjectSpec::Kind::kViewAdaptive;
    return {idle, view};
  }

  const Clip& FindClip(const std::string& name, int line) const {
    const Clip* clip = ch_.character().FindClip(name);
    if (!clip)
      throw Error((line ? At(line) : spec_.where + ": ") + "clip '" + name + "' does not exist in " + ch_.character().source +
                  " (clips: " + ClipList(ch_.character()) + ")");
    return *clip;
  }

  BlendablePtr Object(const ObjectSpec& o) {
    BlendablePtr b;
    switch (o.kind) {
      case ObjectSpec::Kind::kClip:
        b = std::make_shared<ClipSource>(sk_, std::shared_ptr<const Clip>(ch_.shared_character(), &FindClip(o.clip, o.line)),
                                         spec_.nlerp_sampling);
        break;
      case ObjectSpec::Kind::kPose: {
        LocalPose pose = LocalPose::Rest(*sk_);
        if (!o.clip.empty()) MustRun(SamplingJob{sk_.get(), &FindClip(o.clip, o.line), o.pose_time, false, &pose}, "pose");
        b = std::make_shared<StaticPose>(std::move(pose));
        break;
      }
      case ObjectSpec::Kind::kViewAdaptive:
        b = ch_.view_adaptive();
        break;
      case ObjectSpec::Kind::kIdle:
        if (!spec_.idle.given) throw Error(At(o.line) + "'idle: true' needs the character's 'idle:' section");
        if (!idle_) {
          IdleLayerReport report;
          idle_ = BuildIdleLayer(ch_, &report);
          notes_.insert(notes_.end(), report.notes.begin(), report.notes.end());
        }
        b = idle_;
        break;
      case ObjectSpec::Kind::kSchedule: {
        FrameBlenderOptions blender;
        blender.method = spec_.blend;
        blender.dib = spec_.dib;
        blender.rest_threshold = spec_.schedule.rest_threshold;
        auto nested = std::make_shared<Schedule>(sk_, blender, std::min<int>(60, static_cast<int>(o.actions.size()) + 1));
        for (const ActionSpec& a : o.actions) {
          if (a.has_trigger || !a.distance_weight.empty())
            throw Error(At(a.line) + "distance triggers and weights belong to the top-level schedule");
          try {
            nested->Add(MakeAction(a));
          } catch (const Error& e) {
            throw Error(At(a.line) + e.what());
          }
        }
        b = nested;
        break;
      }
    }
    try {
      if (o.has_window) b = std::make_shared<Window>(b, o.window_from, o.window_to);
      if (o.stretch > 0) b = std::make_shared<TimeStretch>(b, o.stretch);
      if (o.loop >= 0) b = std::make_shared<Loop>(b, o.loop);
      if (o.mirror) b = std::make_shared<Mirror>(b, sk_, spec_.up.cross(spec_.forward));
      if (o.has_transform)
        b = std::make_shared<GlobalTransform>(b, sk_, DualQuatd::FromRotationTranslation(o.transform.rotation, o.transform.position));
    } catch (const Error& e) {
      throw Error(At(o.line) + e.what());
    }
    return b;
  }

  JointMask Mask(const MaskSpec& m) const {
    JointMask mask{std::vector<double>(sk_->size(), m.default_rotation), std::vector<double>(sk_->size(), m.default_translation)};
    for (const MaskSpec::Scope& s : m.scopes) {
      std::vector<int> joints;
      try {
        joints = ResolveScope(*sk_, s.name, spec_.scopes);
      } catch (const Error& e) {
        throw Error(At(m.line) + e.what());
      }
      mask.SetRotation(joints, s.rotation);
      mask.SetTranslation(joints, s.translation);
    }
    return mask;
  }

  Action MakeAction(const ActionSpec& a) {
    Action action;
    action.object = Object(a.object);
    action.name = a.name;
    action.start = a.start;
    action.keep_rendering = a.keep_rendering;
    action.layer = a.layer;
    action.params.gain = a.weight;
    action.params.curves = a.curves;
    action.params.scalings = a.scalings;
    for (const MaskSpec& m : a.masks) action.params.masks.push_back(Mask(m));
    return action;
  }

  const AnimatedCharacter& ch_;
  const CharacterSpec& spec_;
  std::shared_ptr<const Skeleton> sk_;
  AnimatorOverrides overrides_;
  std::string file_;
  BlendablePtr idle_;
  std::vector<std::string> notes_;  // what the user should be told (IdleLayerReport::notes)
};

// "scene.yaml:<line>: <what>: ", for the idle section's messages.
std::string IdleWhere(const CharacterSpec& spec, int line, const std::string& what) {
  return spec.where.substr(0, spec.where.rfind(':')) + ":" + std::to_string(line) + ": " + what + ": ";
}

// The idle section's learning options and sources (the loaded motion files kept in `motion`).
struct IdleLearningInput {
  std::vector<Character> motion;
  std::vector<IdleSource> sources;
  IdleLearningOptions options;
};

std::unique_ptr<IdleLearningInput> IdleInput(const AnimatedCharacter& ch) {
  const CharacterSpec& spec = ch.spec();
  const std::string where = IdleWhere(spec, spec.idle.line, "idle");
  auto in = std::make_unique<IdleLearningInput>();
  in->motion.reserve(spec.idle.motion.size());
  for (const auto& f : spec.idle.motion) in->motion.push_back(LoadCharacter(f));
  for (const Character& m : in->motion) {
    IdleSource s{&m, {}, false};
    for (const Clip& c : m.clips) s.clips.push_back(&c);
    in->sources.push_back(s);
  }
  if (!spec.idle.clips.empty()) {
    IdleSource own{&ch.character(), {}, true};
    for (const std::string& name : spec.idle.clips) {
      const Clip* c = ch.character().FindClip(name);
      if (!c) throw Error(where + "clip '" + name + "' does not exist in " + ch.character().source);
      own.clips.push_back(c);
    }
    in->sources.push_back(own);
  }
  in->options.components = spec.idle.components;
  in->options.joint_map = spec.idle.joint_map;
  in->options.forward = spec.forward;
  in->options.up = spec.up;
  return in;
}

std::shared_ptr<IdleModel> LearnIdle(const AnimatedCharacter& ch, const IdleLearningInput& in, std::string* summary) {
  const CharacterSpec& spec = ch.spec();
  IdleLearningReport report;
  std::shared_ptr<IdleModel> model;
  try {
    model = std::make_shared<IdleModel>(LearnIdleModel(ch.character().skeleton, in.sources, in.options, &report));
  } catch (const Error& e) {
    throw Error(IdleWhere(spec, spec.idle.line, "idle") + e.what());
  }
  if (summary) *summary = report.Summary();
  return model;
}

// The balance-shift model of `idle.balance:` (nothing when its recording holds no transition),
// in the idle model's posture layout.
std::shared_ptr<const BalanceModel> LearnBalance(const AnimatedCharacter& ch, const IdleModel& idle, const IdleLearningInput& in,
                                                 BalanceLearningReport& report) {
  const CharacterSpec& spec = ch.spec();
  const BalanceSpec& b = spec.idle.balance;
  const std::string where = IdleWhere(spec, b.line, "idle.balance");
  try {
    std::optional<Character> recording;
    IdleSource source{&ch.character(), {}, true};
    BalanceLearningOptions options;
    options.components = b.components;
    options.analysis.up = spec.up;
    if (!b.motion.empty()) {
      recording = LoadCharacter(b.motion);
      source = {&*recording, {}, false};
      for (const Clip& c : recording->clips) source.clips.push_back(&c);
      options.analysis.up = Eigen::Vector3d::UnitY();  // motion capture's up, as the idle learner reads it
    } else {
      const Clip* c = ch.character().FindClip(b.clip);
      if (!c)
        throw Error("clip '" + b.clip + "' does not exist in " + ch.character().source + " (clips: " + ClipList(ch.character()) +
                    ")");
      source.clips.push_back(c);
    }
    std::optional<BalanceModel> model =
        LearnBalanceModel(ch.character().skeleton, source, idle, in.options, options, &report);
    return model ? std::make_shared<const BalanceModel>(std::move(*model)) : nullptr;
  } catch (const Error& e) {
    throw Error(where + e.what());
  }
}

}  // namespace

std::shared_ptr<IdleSynthesizer> BuildIdle(const AnimatedCharacter& ch, std::string* summary) {
  const auto in = IdleInput(ch);
  return std::make_shared<IdleSynthesizer>(ch.shared_skeleton(), LearnIdle(ch, *in, summary), ch.spec().idle.seed);
}

BlendablePtr BuildIdleLayer(const AnimatedCharacter& ch, IdleLayerReport* report) {
  IdleLayerReport rep;
  const auto in = IdleInput(ch);
  const std::shared_ptr<IdleModel> idle_model = LearnIdle(ch, *in, &rep.idle);
  auto idle = std::make_shared<IdleSynthesizer>(ch.shared_skeleton(), idle_model, ch.spec().idle.seed);
  BlendablePtr layer = idle;
  const BalanceSpec& b = ch.spec().idle.balance;
  if (b.given) {
    BalanceLearningReport balance;
    if (auto model = LearnBalance(ch, *idle_model, *in, balance)) {
      layer = std::make_shared<BalanceShifter>(ch.shared_skeleton(), model, b.seed, idle);
      rep.balance_built = true;
    } else {
      rep.notes.push_back(IdleWhere(ch.spec(), b.line, "idle.balance") + balance.Summary() +
                          "; the character idles without balance shifts");
    }
    rep.balance = balance.Summary();
  }
  if (report) *report = std::move(rep);
  return layer;
}

std::unique_ptr<Animator> BuildAnimator(const AnimatedCharacter& character, const AnimatorOverrides& overrides,
                                        std::vector<std::string>* notes) {
  AnimatorBuilder builder(character, overrides);
  std::unique_ptr<Animator> animator = builder.Build();
  if (notes) *notes = builder.notes();
  return animator;
}

}  // namespace arview::anim
