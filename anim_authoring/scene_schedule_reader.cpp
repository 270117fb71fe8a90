#include "anim_authoring/scene_reader.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

namespace arview::authoring {

namespace fs = std::filesystem;
using Node = yaml::Node;

anim::ScopeTable SceneReader::Scopes(const Node& n) const {
  if (!n.IsMapping()) Fail(n, "scopes must be a mapping of name: [joints]");
  anim::ScopeTable table;
  for (const auto& [name, v] : n.entries) {
    anim::ScopeSpec spec;
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

IdleSpec SceneReader::Idle(const Node& n, const fs::path& base_dir) const {
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

BalanceSpec SceneReader::Balance(const Node& n, const fs::path& base_dir, int idle_components) const {
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

anim::Curve SceneReader::CurveOf(const Node& n, const std::string& what) const {
  OnlyKeys(n, {"shape", "in", "out", "attack", "decay", "sustain", "release", "peak", "seconds"}, what);
  anim::Curve c;
  if (const Node* x = n.Find("shape"))
    c.shape = Choice<anim::Curve::Shape>(*x, what + ".shape",
                                   {{"constant", anim::Curve::Shape::kConstant},
                                    {"linear-fade", anim::Curve::Shape::kLinearFade},
                                    {"cosine-fade", anim::Curve::Shape::kCosineFade},
                                    {"adsr", anim::Curve::Shape::kAdsr},
                                    {"cosine-adsr", anim::Curve::Shape::kCosineAdsr}});
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

std::vector<anim::Curve> SceneReader::Curves(const Node& n, const std::string& what) const {
  std::vector<anim::Curve> out;
  if (n.IsSequence())
    for (const Node& c : n.items) out.push_back(CurveOf(c, what));
  else
    out.push_back(CurveOf(n, what));
  return out;
}

std::pair<double, double> SceneReader::MaskWeight(const Node& n, const std::string& what) const {
  if (n.IsMapping()) {
    OnlyKeys(n, {"rotation", "translation"}, what);
    const Node* r = n.Find("rotation");
    const Node* t = n.Find("translation");
    return {r ? NonNegative(*r, what + ".rotation") : 1.0, t ? NonNegative(*t, what + ".translation") : 1.0};
  }
  const double w = NonNegative(n, what);
  return {w, w};
}

MaskSpec SceneReader::MaskOf(const Node& n) const {
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

ObjectSpec SceneReader::ObjectOf(const Node& n) const {
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

ActionSpec SceneReader::ActionOf(const Node& n) const {
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

ScheduleSpec SceneReader::ScheduleOf(const Node& n) const {
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

}  // namespace arview::authoring
