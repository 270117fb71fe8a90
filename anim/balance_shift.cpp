#include "anim/balance_shift.h"

#include "anim/seeded_draw.h"

#include <algorithm>
#include <cmath>

namespace arview::anim {

const char* SupportName(Support s) {
  switch (s) {
    case Support::kLeft: return "left";
    case Support::kBoth: return "both";
    case Support::kRight: return "right";
  }
  return "?";
}

bool BalanceModel::CanLeave(Support c) const {
  for (int n : counts[static_cast<int>(c)])
    if (n > 0) return true;
  return false;
}

double BalanceModel::Probability(Support from, Support to) const {
  const auto& row = counts[static_cast<int>(from)];
  const int total = row[0] + row[1] + row[2];
  return total > 0 ? static_cast<double>(row[static_cast<int>(to)]) / total : 0.0;
}

// Per component i the change of its value, C_iᵀ(a − b), without a temporary vector: chosen on
// the frame a transition starts, which allocates nothing.
double BalanceModel::Distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const {
  double sum = 0;
  for (int i = 0; i < eigenvalues.size(); ++i) {
    const double change = components.col(i).dot(a - b);
    sum += eigenvalues[i] * change * change;
  }
  return std::sqrt(sum);
}

void BalanceModel::Check(int skeleton_joints) const {
  const int d = 3 * static_cast<int>(joints.size()) + 3;
  if (mean.size() != d || components.rows() != d || components.cols() != eigenvalues.size() || eigenvalues.size() == 0)
    throw Error("balance model: sizes disagree");
  for (int j : joints)
    if (j < 0 || j >= skeleton_joints) throw Error("balance model: joint index out of range");
  if (root < 0 || root >= skeleton_joints) throw Error("balance model: root out of range");
  for (const Segment& s : segments) {
    if (s.frames.size() < 2 || !(s.rate > 0)) throw Error("balance model: a segment shorter than two frames");
    for (const auto& f : s.frames)
      if (f.size() != d) throw Error("balance model: a segment's posture has the wrong size");
  }
  bool any = false;
  for (int c = 0; c < kSupports; ++c) {
    const Support from = static_cast<Support>(c);
    if (!CanLeave(from)) continue;
    any = true;
    if (rests[c].empty()) throw Error(std::string("balance model: no resting posture in category ") + SupportName(from));
    for (const auto& r : rests[c])
      if (r.size() != d) throw Error("balance model: a resting posture has the wrong size");
    if (!(dwell_min[c] >= 0 && dwell_min[c] <= dwell_max[c])) throw Error("balance model: a dwell range is empty");
    for (int s = 0; s < kSupports; ++s) {
      if (counts[c][s] <= 0) continue;
      const Support to = static_cast<Support>(s);
      if (!CanLeave(to)) throw Error(std::string("balance model: category ") + SupportName(to) + " cannot be left");
      if (ChooseSegment(*this, from, to, rests[c].front(), rests[c].front()) < 0)
        throw Error("balance model: a transition without a recorded segment");
    }
  }
  if (!any) throw Error("balance model: no category with a transition out");
}

int ChooseSegment(const BalanceModel& model, Support from, Support to, const Eigen::VectorXd& p, const Eigen::VectorXd& q) {
  int best = -1;
  double best_distance = 0;
  for (std::size_t i = 0; i < model.segments.size(); ++i) {
    const BalanceModel::Segment& a = model.segments[i];
    if (a.from != from || a.to != to) continue;
    const double d = std::max(model.Distance(a.frames.front(), p), model.Distance(a.frames.back(), q));
    if (best < 0 || d < best_distance) {
      best = static_cast<int>(i);
      best_distance = d;
    }
  }
  return best;
}

void FittedPosture(const BalanceModel::Segment& a, const Eigen::VectorXd& p, const Eigen::VectorXd& q, double u,
                   Eigen::VectorXd& out) {
  u = std::clamp(u, 0.0, 1.0);
  const std::size_t last = a.frames.size() - 1;
  const double at = u * static_cast<double>(last);
  const std::size_t i = std::min(last - 1, static_cast<std::size_t>(at));
  const double f = at - static_cast<double>(i);
  out = a.frames[i] + f * (a.frames[i + 1] - a.frames[i]) + (1 - u) * (p - a.frames.front()) + u * (q - a.frames.back());
}

BalanceShifter::BalanceShifter(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<const BalanceModel> model,
                               std::uint64_t seed, std::shared_ptr<IdleSynthesizer> variations)
    : skeleton_(std::move(skeleton)), model_(std::move(model)), seed_(seed), variations_(std::move(variations)) {
  if (!skeleton_ || !model_) throw Error("balance shifter: no skeleton or model");
  model_->Check(skeleton_->size());
  if (variations_ && (variations_->model().joints != model_->joints || variations_->model().root != model_->root))
    throw Error("balance shifter: the idle synthesizer varies other joints than the balance model");
  p_ = q_ = posture_ = model_->mean;
  rest_ = LocalPose::Rest(*skeleton_);
  Restart();
}

const Eigen::VectorXd& BalanceShifter::DrawRest(Support c) {
  const auto& postures = model_->rests[static_cast<int>(c)];
  return postures[std::min(postures.size() - 1, static_cast<std::size_t>(Uniform(rng_) * postures.size()))];
}

// The thesis's pause (§4.1.2): a minimum p_m (the shortest recorded rest) and a random offset up to
// p_o (to the longest), the offset scaled by the activation's factor. One draw whatever the scale,
// so that streams under different scales make the same choices.
double BalanceShifter::DrawDwell(Support c) {
  const int i = static_cast<int>(c);
  const double offset = model_->dwell_max[i] - model_->dwell_min[i];
  return model_->dwell_min[i] + Uniform(rng_) * offset * pause_offset_scale_;
}

void BalanceShifter::SetPauseOffsetScale(double scale) {
  pause_offset_scale_ = std::isfinite(scale) && scale >= 0 ? scale : 1.0;
}

// The first rest: a category that can be left, drawn evenly (the thesis's "random category"),
// one of its resting postures, and a seeded phase inside its dwell, so that streams of
// different seeds differ from the start.
void BalanceShifter::Restart() {
  rng_.seed(seed_ * 0x9E3779B97F4A7C15ull + 0x94D049BB133111EBull);
  std::array<double, kSupports> leavable{};
  for (int c = 0; c < kSupports; ++c) leavable[c] = model_->CanLeave(static_cast<Support>(c)) ? 1 : 0;
  const Support c = static_cast<Support>(Draw(rng_, leavable));
  p_ = DrawRest(c);
  const double dwell = DrawDwell(c);
  const double phase = Uniform(rng_) * dwell;
  state_ = {-1, c, c, -phase, dwell - phase};
}

void BalanceShifter::NextState() {
  const double t = state_.t1;
  if (state_.segment < 0) {  // rest → transition to a category drawn by the recorded counts
    const Support from = state_.from;
    const Support to = static_cast<Support>(Draw(rng_, model_->counts[static_cast<int>(from)]));
    q_ = DrawRest(to);
    const int segment = ChooseSegment(*model_, from, to, p_, q_);
    state_ = {segment, from, to, t, t + model_->segments[segment].Seconds()};
  } else {  // transition → rest at its end posture
    const Support c = state_.to;
    p_ = q_;
    state_ = {-1, c, c, t, t + DrawDwell(c)};
  }
}

void BalanceShifter::Advance(double t) {
  if (t < state_.t0) Restart();  // backwards: replay from the seed
  while (t >= state_.t1) NextState();
}

const Eigen::VectorXd& BalanceShifter::Posture(double t) {
  if (!std::isfinite(t)) t = 0;
  Advance(t);
  if (state_.segment < 0) {
    posture_ = p_;
  } else {
    FittedPosture(model_->segments[state_.segment], p_, q_, (t - state_.t0) / (state_.t1 - state_.t0), posture_);
  }
  return posture_;
}

bool BalanceShifter::Sample(double t, const FrameInputs& inputs, LocalPose& out) {
  if (out.size() != skeleton_->size()) return false;
  SetPauseOffsetScale(inputs.pause_offset_scale);
  Posture(t);
  if (variations_) posture_ += variations_->Posture(t) - variations_->model().mean;
  PoseFromPosture(*skeleton_, rest_, model_->joints, model_->root, posture_, out);
  return true;
}

}  // namespace arview::anim
