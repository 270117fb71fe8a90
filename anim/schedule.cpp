#include "anim/schedule.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace arview::anim {
namespace {

// The rotation of `q` scaled about the rest rotation: rest · (rest⁻¹ q)^s.
Eigen::Quaterniond ScaleAboutRest(const Eigen::Quaterniond& q, const Eigen::Quaterniond& rest, double s) {
  Eigen::Quaterniond delta = rest.conjugate() * q;
  if (delta.w() < 0) delta.coeffs() = -delta.coeffs();
  const Eigen::AngleAxisd aa(delta.normalized());
  return rest * Eigen::Quaterniond(Eigen::AngleAxisd(aa.angle() * s, aa.axis()));
}

constexpr int kMaxContributors = BlendingJob::kMaxInputs;

}  // namespace

double Schedule::GainFade::At(double t) const {
  if (seconds <= 0 || t >= start + seconds) return t >= start ? to : from;
  if (t <= start) return from;
  const double x = (t - start) / seconds;
  return from + (to - from) * 0.5 * (1 - std::cos(M_PI * x));
}

Schedule::Schedule(std::shared_ptr<const Skeleton> skeleton, const FrameBlenderOptions& options, int capacity)
    : skeleton_(std::move(skeleton)), options_(options) {
  if (!skeleton_) throw Error("schedule: no skeleton");
  if (capacity < 1 || capacity >= kMaxContributors) throw Error("schedule: capacity must be in 1..63");
  if (!(options_.rest_threshold >= 0)) throw Error("schedule: rest_threshold must be non-negative");
  slots_.resize(capacity);
  for (Slot& s : slots_) {
    s.pose.Resize(skeleton_->size(), skeleton_->morph_target_count());
    s.mask_rotation.assign(skeleton_->size(), 1.0);
    s.mask_translation.assign(skeleton_->size(), 1.0);
  }
  active_.reserve(capacity);
  rest_ = LocalPose::Rest(*skeleton_);
}

int Schedule::free_count() const {
  return static_cast<int>(std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) { return !s.used; }));
}

int Schedule::Add(Action action) {
  const std::string what = "action '" + action.name + "'";
  if (!action.object) throw Error(what + ": no object");
  if (action.object->joint_count() != skeleton_->size())
    throw Error(what + ": its object animates " + std::to_string(action.object->joint_count()) + " joints, the skeleton has " +
                std::to_string(skeleton_->size()));
  if (!std::isfinite(action.start)) throw Error(what + ": start time must be finite");
  const double length = action.object->Duration();
  for (const auto* curves : {&action.params.curves, &action.params.scalings})
    for (const Curve& c : *curves)
      if (const std::string why = c.Check(length); !why.empty()) throw Error(what + ": " + why);
  for (const JointMask& m : action.params.masks) {
    if (m.size() != skeleton_->size() || static_cast<int>(m.translation.size()) != skeleton_->size())
      throw Error(what + ": mask size differs from the joint count");
    for (int j = 0; j < m.size(); ++j)
      if (!(m.rotation[j] >= 0) || !(m.translation[j] >= 0) || !std::isfinite(m.rotation[j] + m.translation[j]))
        throw Error(what + ": mask weights must be finite and non-negative");
  }
  if (!(action.params.gain >= 0) || !std::isfinite(action.params.gain)) throw Error(what + ": gain must be finite, >= 0");
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    if (s.used) continue;
    s.used = true;
    s.action = std::move(action);
    s.gain = GainFade{};
    s.live = 1;
    s.weight = 0;
    s.length = length;
    for (int j = 0; j < skeleton_->size(); ++j) {
      s.mask_rotation[j] = s.action.params.MaskRotation(j);
      s.mask_translation[j] = s.action.params.MaskTranslation(j);
    }
    return static_cast<int>(i);
  }
  throw Error(what + ": the schedule is full (" + std::to_string(slots_.size()) + " actions)");
}

bool Schedule::Remove(int id) {
  if (id < 0 || id >= static_cast<int>(slots_.size()) || !slots_[id].used) return false;
  slots_[id].used = false;
  slots_[id].action = Action{};
  return true;
}

bool Schedule::Retime(int id, double start) {
  if (!Find(id) || !std::isfinite(start)) return false;
  slots_[id].action.start = start;
  return true;
}

bool Schedule::FadeGain(int id, double target, double now, double seconds) {
  if (!Find(id) || !std::isfinite(target) || target < 0 || !std::isfinite(now) || !(seconds >= 0)) return false;
  GainFade& g = slots_[id].gain;
  g = GainFade{g.At(now), target, now, seconds};
  return true;
}

bool Schedule::SetLiveWeight(int id, double weight) {
  if (!Find(id) || !(weight >= 0) || !std::isfinite(weight)) return false;
  slots_[id].live = weight;
  return true;
}

double Schedule::Gain(int id, double t) const { return Find(id) ? slots_[id].gain.At(t) : 0.0; }

const Action* Schedule::Find(int id) const {
  if (id < 0 || id >= static_cast<int>(slots_.size()) || !slots_[id].used) return nullptr;
  return &slots_[id].action;
}

int Schedule::FindByName(const std::string& name) const {
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].used && slots_[i].action.name == name) return static_cast<int>(i);
  return -1;
}

double Schedule::last_weight(int id) const { return Find(id) ? slots_[id].weight : 0.0; }

double Schedule::Duration() const {
  double end = 0;
  for (const Slot& s : slots_) {
    if (!s.used) continue;
    if (s.action.keep_rendering || !std::isfinite(s.length)) return kUnbounded;
    end = std::max(end, s.action.start + s.length);
  }
  return end;
}

bool Schedule::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  if (out.size() != skeleton_->size() || !std::isfinite(t)) return false;
  if (!out.morph.empty() && static_cast<int>(out.morph.size()) != skeleton_->morph_target_count()) return false;
  active_.clear();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    s.weight = 0;
    if (!s.used) continue;
    const double local = t - s.action.start;
    if (local < 0 || (local > s.length && !s.action.keep_rendering)) continue;
    const double at = std::min(local, s.length);
    s.weight = s.live * s.gain.At(t) * s.action.params.TimeWeight(at, s.length);
    if (!(s.weight > 0)) {
      s.weight = 0;
      continue;
    }
    s.scaling = s.action.params.Scaling(at, s.length);
    s.pose.morph_keyed = false;  // set by an object that keys the face
    if (!s.action.object->Sample(at, inputs, s.pose)) return false;
    active_.push_back(static_cast<int>(i));
  }
  // Layers bottom to top (insertion sort: a handful of actions, stable, no allocation).
  for (std::size_t i = 1; i < active_.size(); ++i)
    for (std::size_t k = i; k > 0 && slots_[active_[k - 1]].action.layer > slots_[active_[k]].action.layer; --k)
      std::swap(active_[k - 1], active_[k]);
  Blend(out);
  BlendMorph(out);
  return true;
}

namespace {

// Contributors of one joint: transforms, rotation and translation weights, scales.
struct JointInputs {
  std::array<DualQuatd, kMaxContributors> q;
  std::array<double, kMaxContributors> wr, wt;
  std::array<Eigen::Vector3d, kMaxContributors> scale;
  int n = 0;
  double sum_r = 0, sum_t = 0;
  bool same = true;  // rotation and translation weights agree for every contributor

  void Clear() { n = 0; sum_r = sum_t = 0; same = true; }
  void Add(const DualQuatd& x, double r, double t, const Eigen::Vector3d& s) {
    q[n] = x;
    wr[n] = r;
    wt[n] = t;
    scale[n] = s;
    same = same && r == t;
    sum_r += r;
    sum_t += t;
    ++n;
  }
};

// The normalised blend of a joint's contributors (n ≥ 1, some weight > 0).
void BlendJoint(JointInputs& in, const FrameBlenderOptions& options, DualQuatd& out_q, Eigen::Vector3d& out_scale,
                bool& converged) {
  if (in.n == 1) {  // unchanged: a masked layer leaves what it does not cover exact
    out_q = in.q[0];
    out_scale = in.scale[0];
    return;
  }
  Eigen::Vector3d scale = Eigen::Vector3d::Zero();
  for (int k = 0; k < in.n; ++k) {
    in.wr[k] /= in.sum_r > 0 ? in.sum_r : 1.0;
    in.wt[k] /= in.sum_t > 0 ? in.sum_t : 1.0;
    scale += (in.sum_r > 0 ? in.wr[k] : 1.0 / in.n) * in.scale[k];
  }
  out_scale = scale;
  const std::span<const DualQuatd> qs(in.q.data(), in.n);
  if (in.same) {
    const std::span<const double> ws(in.wr.data(), in.n);
    if (options.method == BlendMethod::kDlb) {
      out_q = Dlb<double>(qs, ws);
    } else {
      const DibResult<double> r = Dib<double>(qs, ws, options.dib);
      out_q = r.q;
      converged = converged && r.converged;
    }
    return;
  }
  // Rotation and translation apart: sign-aligned normalised sum, weighted mean.
  int pivot = 0;
  for (int k = 1; k < in.n; ++k)
    if (in.wr[k] > in.wr[pivot]) pivot = k;
  Eigen::Vector4d r = Eigen::Vector4d::Zero();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (int k = 0; k < in.n; ++k) {
    const double sign = in.q[k].RealDot(in.q[pivot]) < 0 ? -1.0 : 1.0;
    r += sign * in.wr[k] * in.q[k].real().coeffs();
    t += in.wt[k] * in.q[k].Translation();
  }
  Eigen::Quaterniond rotation(r);
  if (!(rotation.norm() > 1e-12)) rotation = in.q[pivot].Rotation();
  out_q = DualQuatd::FromRotationTranslation(rotation.normalized(), t);
}

}  // namespace

void Schedule::Blend(LocalPose& out) {
  const Skeleton& sk = *skeleton_;
  JointInputs in;
  converged_ = true;
  const int active_count = static_cast<int>(active_.size());
  // One layer's contributors to the joint: slot and rotation and translation weights.
  std::array<int, kMaxContributors> slot;
  std::array<double, kMaxContributors> wr, wt;
  for (int j = 0; j < sk.size(); ++j) {
    DualQuatd below = rest_.rigid[j];
    Eigen::Vector3d below_scale = rest_.scale[j];
    for (int a = 0; a < active_count;) {
      const int layer = slots_[active_[a]].action.layer;
      int n = 0;
      for (; a < active_count && slots_[active_[a]].action.layer == layer; ++a) {
        const Slot& s = slots_[active_[a]];
        const double r = s.weight * s.mask_rotation[j];
        const double tr = s.weight * s.mask_translation[j];
        if (r <= 0 && tr <= 0) continue;
        slot[n] = active_[a];
        wr[n] = r;
        wt[n] = tr;
        ++n;
      }
      // Nothing on this layer: what is below stays (it would fill the layer alone).
      if (n == 0) continue;
      auto pose_of = [&](const Slot& s) {
        const DualQuatd& q = s.pose.rigid[j];
        if (s.scaling == 1) return q;
        return DualQuatd::FromRotationTranslation(ScaleAboutRest(q.Rotation(), sk.rest[j].rotation, s.scaling), q.Translation());
      };
      // What is below fills the layer up: to the rest threshold on layer 0 (ozz), to 1 above.
      const bool bottom = layer == slots_[active_[0]].action.layer;
      const double fill = bottom ? options_.rest_threshold : 1.0;
      // One contributor that fills the layer alone: its pose, unchanged.
      if (n == 1 && wr[0] >= fill && wt[0] >= fill) {
        const Slot& s = slots_[slot[0]];
        below = pose_of(s);
        below_scale = s.pose.scale[j];
        continue;
      }
      in.Clear();
      for (int k = 0; k < n; ++k) {
        const Slot& s = slots_[slot[k]];
        in.Add(pose_of(s), wr[k], wt[k], s.pose.scale[j]);
      }
      const double below_r = std::max(0.0, fill - in.sum_r), below_t = std::max(0.0, fill - in.sum_t);
      if (below_r > 0 || below_t > 0) in.Add(below, below_r, below_t, below_scale);
      BlendJoint(in, options_, below, below_scale, converged_);
    }
    out.rigid[j] = below;
    out.scale[j] = below_scale;
  }
}

void Schedule::BlendMorph(LocalPose& out) const {
  out.morph_keyed = false;
  if (out.morph.empty()) return;
  std::fill(out.morph.begin(), out.morph.end(), 0.f);  // the rest: no target weighted
  const int active_count = static_cast<int>(active_.size());
  for (int a = 0; a < active_count;) {
    const int first = a;
    const int layer = slots_[active_[a]].action.layer;
    double total = 0;
    for (; a < active_count && slots_[active_[a]].action.layer == layer; ++a)
      if (slots_[active_[a]].pose.morph_keyed) total += slots_[active_[a]].weight;
    if (total <= 0) continue;  // nothing on this layer keys the face: what is below stays
    // As the joints: what is below fills the layer up to the threshold on layer 0, to 1 above.
    const double fill = first == 0 ? options_.rest_threshold : 1.0;
    const double norm = std::max(total, fill);
    const auto below = static_cast<float>(std::max(0.0, fill - total) / norm);
    for (float& w : out.morph) w *= below;
    for (int k = first; k < a; ++k) {
      const Slot& s = slots_[active_[k]];
      if (!s.pose.morph_keyed) continue;
      const auto f = static_cast<float>(s.weight / norm);
      for (std::size_t i = 0; i < out.morph.size(); ++i) out.morph[i] += f * s.pose.morph[i];
    }
    out.morph_keyed = true;
  }
}

}  // namespace arview::anim
