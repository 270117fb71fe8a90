#include "anim_authoring/animator_builder.h"

#include "anim_authoring/balance.h"
#include "anim_authoring/idle_learning.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace arview::authoring {

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

  std::unique_ptr<anim::Animator> Build() {
    anim::FrameBlenderOptions blender;
    blender.method = spec_.blend;
    blender.dib = spec_.dib;
    blender.rest_threshold = spec_.schedule.rest_threshold;
    std::vector<ActionSpec> actions = spec_.schedule.given ? spec_.schedule.actions : DefaultActions();
    int triggers = 0;
    for (const ActionSpec& a : actions) triggers += a.has_trigger;
    auto schedule = std::make_shared<anim::Schedule>(
        sk_, blender, std::min<int>(60, static_cast<int>(actions.size()) + 4 * triggers + 4) + std::max(0, overrides_.played_actions));
    anim::AnimatorOptions options;
    options.view_action = spec_.schedule.view_action;
    options.hold_seconds = overrides_.hold_seconds.value_or(spec_.schedule.hold_seconds);
    options.fade_seconds = overrides_.fade_seconds.value_or(spec_.schedule.fade_seconds);
    options.gaze = ch_.gaze();
    options.face = overrides_.face;
    for (std::size_t i = 0; i < actions.size(); ++i) {
      ActionSpec a = actions[i];
      if (a.name.empty()) a.name = "action" + std::to_string(i + 1);
      anim::Action action = MakeAction(a);
      if (a.has_trigger) {
        options.triggers.push_back({a.trigger_near, a.trigger_far, std::move(action)});
        continue;
      }
      try {
        schedule->Add(std::move(action));
      } catch (const anim::Error& e) {
        throw anim::Error(At(a.line) + e.what());
      }
      if (!a.distance_weight.empty()) options.distance_weights.push_back({a.name, a.distance_weight});
    }
    if (!options.view_action.empty() && schedule->FindByName(options.view_action) < 0) options.view_action.clear();
    try {
      return std::make_unique<anim::Animator>(sk_, schedule, std::move(options), ch_.view_adaptive());
    } catch (const anim::Error& e) {
      throw anim::Error(spec_.where + ": " + e.what());
    }
  }

 private:
  std::string At(int line) const { return file_ + ":" + std::to_string(line) + ": "; }

  std::vector<ActionSpec> DefaultActions() const {
    ActionSpec idle;
    idle.name = "idle";
    idle.keep_rendering = true;
    idle.line = 0;
    const anim::Character& c = ch_.character();
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

  const anim::Clip& FindClip(const std::string& name, int line) const {
    const anim::Clip* clip = ch_.character().FindClip(name);
    if (!clip)
      throw anim::Error((line ? At(line) : spec_.where + ": ") + "clip '" + name + "' does not exist in " + ch_.character().source +
                  " (clips: " + ClipList(ch_.character()) + ")");
    return *clip;
  }

  anim::BlendablePtr Object(const ObjectSpec& o) {
    anim::BlendablePtr b;
    switch (o.kind) {
      case ObjectSpec::Kind::kClip:
        b = std::make_shared<anim::ClipSource>(sk_, std::shared_ptr<const anim::Clip>(ch_.shared_character(), &FindClip(o.clip, o.line)),
                                         spec_.nlerp_sampling);
        break;
      case ObjectSpec::Kind::kPose: {
        anim::LocalPose pose = anim::LocalPose::Rest(*sk_);
        if (!o.clip.empty()) anim::MustRun(anim::SamplingJob{sk_.get(), &FindClip(o.clip, o.line), o.pose_time, false, &pose}, "pose");
        b = std::make_shared<anim::StaticPose>(std::move(pose));
        break;
      }
      case ObjectSpec::Kind::kViewAdaptive:
        b = ch_.view_adaptive();
        break;
      case ObjectSpec::Kind::kIdle:
        if (!spec_.idle.given) throw anim::Error(At(o.line) + "'idle: true' needs the character's 'idle:' section");
        if (!idle_) {
          IdleLayerReport report;
          idle_ = BuildIdleLayer(ch_, &report);
          notes_.insert(notes_.end(), report.notes.begin(), report.notes.end());
        }
        b = idle_;
        break;
      case ObjectSpec::Kind::kSchedule: {
        anim::FrameBlenderOptions blender;
        blender.method = spec_.blend;
        blender.dib = spec_.dib;
        blender.rest_threshold = spec_.schedule.rest_threshold;
        auto nested = std::make_shared<anim::Schedule>(sk_, blender, std::min<int>(60, static_cast<int>(o.actions.size()) + 1));
        for (const ActionSpec& a : o.actions) {
          if (a.has_trigger || !a.distance_weight.empty())
            throw anim::Error(At(a.line) + "distance triggers and weights belong to the top-level schedule");
          try {
            nested->Add(MakeAction(a));
          } catch (const anim::Error& e) {
            throw anim::Error(At(a.line) + e.what());
          }
        }
        b = nested;
        break;
      }
    }
    try {
      if (o.has_window) b = std::make_shared<anim::Window>(b, o.window_from, o.window_to);
      if (o.stretch > 0) b = std::make_shared<anim::TimeStretch>(b, o.stretch);
      if (o.loop >= 0) b = std::make_shared<anim::Loop>(b, o.loop);
      if (o.mirror) b = std::make_shared<anim::Mirror>(b, sk_, spec_.up.cross(spec_.forward));
      if (o.has_transform)
        b = std::make_shared<anim::GlobalTransform>(b, sk_, anim::DualQuatd::FromRotationTranslation(o.transform.rotation, o.transform.position));
    } catch (const anim::Error& e) {
      throw anim::Error(At(o.line) + e.what());
    }
    return b;
  }

  anim::JointMask Mask(const MaskSpec& m) const {
    anim::JointMask mask{std::vector<double>(sk_->size(), m.default_rotation), std::vector<double>(sk_->size(), m.default_translation)};
    for (const MaskSpec::Scope& s : m.scopes) {
      std::vector<int> joints;
      try {
        joints = anim::ResolveScope(*sk_, s.name, spec_.scopes);
      } catch (const anim::Error& e) {
        throw anim::Error(At(m.line) + e.what());
      }
      mask.SetRotation(joints, s.rotation);
      mask.SetTranslation(joints, s.translation);
    }
    return mask;
  }

  anim::Action MakeAction(const ActionSpec& a) {
    anim::Action action;
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
  std::shared_ptr<const anim::Skeleton> sk_;
  AnimatorOverrides overrides_;
  std::string file_;
  anim::BlendablePtr idle_;
  std::vector<std::string> notes_;  // what the user should be told (IdleLayerReport::notes)
};

// "scene.yaml:<line>: <what>: ", for the idle section's messages.
std::string IdleWhere(const CharacterSpec& spec, int line, const std::string& what) {
  return spec.where.substr(0, spec.where.rfind(':')) + ":" + std::to_string(line) + ": " + what + ": ";
}

// The idle section's learning options and sources (the loaded motion files kept in `motion`).
struct IdleLearningInput {
  std::vector<anim::Character> motion;
  std::vector<IdleSource> sources;
  IdleLearningOptions options;
};

std::unique_ptr<IdleLearningInput> IdleInput(const AnimatedCharacter& ch) {
  const CharacterSpec& spec = ch.spec();
  const std::string where = IdleWhere(spec, spec.idle.line, "idle");
  auto in = std::make_unique<IdleLearningInput>();
  in->motion.reserve(spec.idle.motion.size());
  for (const auto& f : spec.idle.motion) in->motion.push_back(LoadCharacter(f));
  for (const anim::Character& m : in->motion) {
    IdleSource s{&m, {}, false};
    for (const anim::Clip& c : m.clips) s.clips.push_back(&c);
    in->sources.push_back(s);
  }
  if (!spec.idle.clips.empty()) {
    IdleSource own{&ch.character(), {}, true};
    for (const std::string& name : spec.idle.clips) {
      const anim::Clip* c = ch.character().FindClip(name);
      if (!c) throw anim::Error(where + "clip '" + name + "' does not exist in " + ch.character().source);
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

std::shared_ptr<anim::IdleModel> LearnIdle(const AnimatedCharacter& ch, const IdleLearningInput& in, std::string* summary) {
  const CharacterSpec& spec = ch.spec();
  IdleLearningReport report;
  std::shared_ptr<anim::IdleModel> model;
  try {
    model = std::make_shared<anim::IdleModel>(LearnIdleModel(ch.character().skeleton, in.sources, in.options, &report));
  } catch (const anim::Error& e) {
    throw anim::Error(IdleWhere(spec, spec.idle.line, "idle") + e.what());
  }
  if (summary) *summary = report.Summary();
  return model;
}

// The balance-shift model of `idle.balance:` (nothing when its recording holds no transition),
// in the idle model's posture layout.
std::shared_ptr<const anim::BalanceModel> LearnBalance(const AnimatedCharacter& ch, const anim::IdleModel& idle, const IdleLearningInput& in,
                                                 BalanceLearningReport& report) {
  const CharacterSpec& spec = ch.spec();
  const BalanceSpec& b = spec.idle.balance;
  const std::string where = IdleWhere(spec, b.line, "idle.balance");
  try {
    std::optional<anim::Character> recording;
    IdleSource source{&ch.character(), {}, true};
    BalanceLearningOptions options;
    options.components = b.components;
    options.analysis.up = spec.up;
    if (!b.motion.empty()) {
      recording = LoadCharacter(b.motion);
      source = {&*recording, {}, false};
      for (const anim::Clip& c : recording->clips) source.clips.push_back(&c);
      options.analysis.up = Eigen::Vector3d::UnitY();  // motion capture's up, as the idle learner reads it
    } else {
      const anim::Clip* c = ch.character().FindClip(b.clip);
      if (!c)
        throw anim::Error("clip '" + b.clip + "' does not exist in " + ch.character().source + " (clips: " + ClipList(ch.character()) +
                    ")");
      source.clips.push_back(c);
    }
    std::optional<anim::BalanceModel> model =
        LearnBalanceModel(ch.character().skeleton, source, idle, in.options, options, &report);
    return model ? std::make_shared<const anim::BalanceModel>(std::move(*model)) : nullptr;
  } catch (const anim::Error& e) {
    throw anim::Error(where + e.what());
  }
}

}  // namespace

std::shared_ptr<anim::IdleSynthesizer> BuildIdle(const AnimatedCharacter& ch, std::string* summary) {
  const auto in = IdleInput(ch);
  return std::make_shared<anim::IdleSynthesizer>(ch.shared_skeleton(), LearnIdle(ch, *in, summary), ch.spec().idle.seed);
}

anim::BlendablePtr BuildIdleLayer(const AnimatedCharacter& ch, IdleLayerReport* report) {
  IdleLayerReport rep;
  const auto in = IdleInput(ch);
  const std::shared_ptr<anim::IdleModel> idle_model = LearnIdle(ch, *in, &rep.idle);
  auto idle = std::make_shared<anim::IdleSynthesizer>(ch.shared_skeleton(), idle_model, ch.spec().idle.seed);
  anim::BlendablePtr layer = idle;
  const BalanceSpec& b = ch.spec().idle.balance;
  if (b.given) {
    BalanceLearningReport balance;
    if (auto model = LearnBalance(ch, *idle_model, *in, balance)) {
      layer = std::make_shared<anim::BalanceShifter>(ch.shared_skeleton(), model, b.seed, idle);
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

std::unique_ptr<anim::Animator> BuildAnimator(const AnimatedCharacter& character, const AnimatorOverrides& overrides,
                                        std::vector<std::string>* notes) {
  AnimatorBuilder builder(character, overrides);
  std::unique_ptr<anim::Animator> animator = builder.Build();
  if (notes) *notes = builder.notes();
  return animator;
}

}  // namespace arview::authoring
