#include "anim/idle.h"

#include "anim/seeded_draw.h"
#include "anim/taylor_trig.h"

#include <algorithm>
#include <cmath>

namespace arview::anim {
namespace {

// Exponential map: a rotation vector (axis · angle) → quaternion. As Eigen's AngleAxis →
// Quaternion (cos, sin of half the angle), with sin and cos from their series up to π.
Eigen::Quaterniond ExpMap(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-12) return Eigen::Quaterniond::Identity();
  if (!(angle <= M_PI)) return Eigen::Quaterniond(Eigen::AngleAxisd(angle, v / angle));
  const Eigen::Array2d sc = TaylorSinCos(0.5 * angle);
  Eigen::Quaterniond q;
  q.w() = sc[1];
  q.vec() = sc[0] * (v / angle);
  return q;
}

// The normalised shape of a segment at x in [0, 1]: the recorded one linearly interpolated
// between its samples, or a cosine without one.
double SegmentShape(const std::vector<double>* shape, double x) {
  if (!shape || shape->size() < 2) return 0.5 * (1 - std::cos(M_PI * x));
  const double at = x * static_cast<double>(shape->size() - 1);
  const std::size_t i = std::min(shape->size() - 2, static_cast<std::size_t>(at));
  const double f = at - static_cast<double>(i);
  return (*shape)[i] + f * ((*shape)[i + 1] - (*shape)[i]);
}

}  // namespace

void IdleModel::Check(int skeleton_joints) const {
  const int d = 3 * static_cast<int>(joints.size()) + 3;
  if (mean.size() != d || min.size() != d || max.size() != d || components.rows() != d ||
      components.cols() != eigenvalues.size() || static_cast<int>(chains.size()) != eigenvalues.size())
    throw Error("idle model: sizes disagree");
  for (int j : joints)
    if (j < 0 || j >= skeleton_joints) throw Error("idle model: joint index out of range");
  if (root < 0 || root >= skeleton_joints) throw Error("idle model: root out of range");
  if (!(speed_limit >= 0) || (speed_limit > 0 && !(speed_step > 0 && speed_step < 1)))
    throw Error("idle model: speed limit or its step out of range");
  for (const ComponentChain& c : chains) {
    if (c.clusters.empty() || c.transitions.size() != c.clusters.size() || c.frequency.size() != c.clusters.size())
      throw Error("idle model: a component has no extrema");
    for (const auto& members : c.clusters)
      if (members.empty()) throw Error("idle model: an empty cluster");
  }
}

IdleSynthesizer::IdleSynthesizer(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<const IdleModel> model,
                                 std::uint64_t seed)
    : skeleton_(std::move(skeleton)), model_(std::move(model)), seed_(seed) {
  if (!skeleton_ || !model_) throw Error("idle synthesizer: no skeleton or model");
  model_->Check(skeleton_->size());
  walks_.resize(model_->component_count());
  coefficients_ = Eigen::VectorXd::Zero(model_->component_count());
  posture_ = model_->mean;
  rest_ = LocalPose::Rest(*skeleton_);
  const int joints = static_cast<int>(model_->joints.size()), m = model_->component_count();
  joint_reach_.resize(m, joints);
  for (int k = 0; k < joints; ++k)
    for (int i = 0; i < m; ++i) joint_reach_(i, k) = model_->components.block<3, 1>(3 * k, i).norm();
  component_reach_ = joint_reach_.rowwise().maxCoeff();
  chord_change_ = coefficients_;
  for (auto& c : grid_coefficients_) c = coefficients_;
  for (auto& p : grid_postures_) p = posture_;
  Restart();
}

void IdleSynthesizer::Restart() {
  for (int i = 0; i < model_->component_count(); ++i) {
    Walk& w = walks_[i];
    w.rng.seed(seed_ * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(i) * 0xBF58476D1CE4E5B9ull + 1);
    const IdleModel::ComponentChain& chain = model_->chains[i];
    w.cluster = Draw(w.rng, chain.frequency);
    const auto& members = chain.clusters[w.cluster];
    const IdleModel::Extremum& e = members[static_cast<std::size_t>(Uniform(w.rng) * members.size())];
    // Start inside the first segment at a seeded phase, so streams of different seeds differ.
    w.t1 = 0;
    w.v0 = w.v1 = e.value;  // no previous swing: the first may go either way
    Step(i, false);  // the other walks are not placed yet
    const double phase = Uniform(w.rng) * (w.t1 - w.t0);
    w.t0 -= phase;
    w.t1 -= phase;
  }
}

void IdleSynthesizer::Step(int i, bool limit_speed) {
  Walk& w = walks_[i];
  const IdleModel::ComponentChain& chain = model_->chains[i];
  const auto& row = chain.transitions[w.cluster];
  double outgoing = 0;
  for (double c : row) outgoing += c;
  w.cluster = Draw(w.rng, outgoing > 0 ? row : chain.frequency);
  // The next extremum lies on the other side of the current one (after a rise, a fall).
  const double rising = w.v1 - w.v0;
  auto opposite = [&](const IdleModel::Extremum& e) { return rising == 0 || (e.value - w.v1) * rising < 0; };
  const IdleModel::Extremum* pick = nullptr;
  for (int pass = 0; pass < 2 && !pick; ++pass) {
    // First the chosen cluster's members; if none is on the other side, every cluster's.
    std::size_t count = 0;
    for (std::size_t c = 0; c < chain.clusters.size(); ++c)
      if (pass == 1 || static_cast<int>(c) == w.cluster)
        for (const auto& e : chain.clusters[c]) count += opposite(e);
    if (count == 0) continue;
    std::size_t k = std::min(count - 1, static_cast<std::size_t>(Uniform(w.rng) * count));
    for (std::size_t c = 0; c < chain.clusters.size() && !pick; ++c)
      if (pass == 1 || static_cast<int>(c) == w.cluster)
        for (const auto& e : chain.clusters[c])
          if (opposite(e) && k-- == 0) {
            pick = &e;
            break;
          }
  }
  if (!pick) {  // no extremum on the other side at all: any member of the chosen cluster
    const auto& members = chain.clusters[w.cluster];
    pick = &members[std::min(members.size() - 1, static_cast<std::size_t>(Uniform(w.rng) * members.size()))];
  }
  // No faster than the recorded segment ending at the drawn extremum.
  double dt = std::max(pick->dt, 1e-3);
  const double recorded_speed = std::abs(pick->rise) / dt;
  if (recorded_speed > 1e-12) dt = std::max(dt, std::abs(pick->value - w.v1) / recorded_speed);
  w.t0 = w.t1;
  w.v0 = w.v1;
  w.t1 = w.t0 + dt;
  w.v1 = pick->value;
  w.shape = &pick->shape;
  if (limit_speed && model_->speed_limit > 0) KeepWithinDataSpeed(i);
}

double IdleSynthesizer::Value(const Walk& w, double t) {
  const double x = (t - w.t0) / (w.t1 - w.t0);
  return w.v0 + (w.v1 - w.v0) * SegmentShape(w.shape, std::clamp(x, 0.0, 1.0));
}

void IdleSynthesizer::ClampedPosture(const Eigen::VectorXd& coefficients, Eigen::VectorXd& posture) const {
  posture.noalias() = model_->components * coefficients;
  posture += model_->mean;
  posture = posture.cwiseMax(model_->min).cwiseMin(model_->max);
}

const Eigen::VectorXd& IdleSynthesizer::GridPosture(int n) {
  const int slot = n % 3;
  if (grid_posture_at_[slot] != n) {
    ClampedPosture(grid_coefficients_[slot], grid_postures_[slot]);
    grid_posture_at_[slot] = n;
  }
  return grid_postures_[slot];
}

// Chords every half step, each one step long; chord n joins grid points n − 2 and n. A joint's
// rotation over a chord turns by at most the length of the change of its rotation vector (the
// exponential map shortens distances: its differential has norm ≤ 1), clamping each value
// into its range only shortens that change, and the change of joint k's three rows is
// Σ_i C_k,i Δc_i, of length ≤ Σ_i |C_k,i| |Δc_i| (|C_k,i|: joint_reach_). So a chord whose
// bound, over all joints (component_reach_) or then per joint, stays a margin below the
// limit's angle passes without reconstructing the posture; only the joints whose bound
// reaches the limit are measured, as before: the two clamped postures rebuilt, the joint's
// rotations by the exponential map and their angular distance. The margin (1e-9 rad) is far
// above the rounding of either computation (~1e-14 rad), so every chord is decided as by
// measuring every joint: the stream is the same bit for bit.
bool IdleSynthesizer::WithinDataSpeed(double from, double to) {
  const double limit = model_->speed_limit, step = model_->speed_step, half = 0.5 * step;
  const double bound = limit * step - 1e-9;
  const int joints = static_cast<int>(model_->joints.size()), m = model_->component_count();
  for (int& at : grid_posture_at_) at = -1;
  for (int n = 0;; ++n) {
    const double t = from - half + n * half;
    Eigen::VectorXd& c = grid_coefficients_[n % 3];
    for (int i = 0; i < m; ++i) c[i] = Value(walks_[i], t);
    if (n >= 2) {
      chord_change_ = (c - grid_coefficients_[(n - 2) % 3]).cwiseAbs();
      if (component_reach_.dot(chord_change_) > bound)
        for (int k = 0; k < joints; ++k) {
          if (joint_reach_.col(k).dot(chord_change_) <= bound) continue;
          const Eigen::VectorXd& before = GridPosture(n - 2);
          const Eigen::VectorXd& now = GridPosture(n);
          if (ExpMap(before.segment<3>(3 * k)).angularDistance(ExpMap(now.segment<3>(3 * k))) / step > limit) return false;
        }
      if (t >= to + half) return true;
    }
  }
}

// Stretch the segment just drawn for component i (its shape kept, its duration longer) until
// the posture of all components together stays within the data's speed over it. Bounded: past
// kMaxStretch the speed is the other components' (they are checked when they step).
void IdleSynthesizer::KeepWithinDataSpeed(int i) {
  constexpr double kMaxStretch = 8, kFactor = 1.25;
  Walk& w = walks_[i];
  const double duration = w.t1 - w.t0;
  for (double stretch = 1;; stretch *= kFactor) {
    w.t1 = w.t0 + duration * stretch;
    if (stretch * kFactor > kMaxStretch || WithinDataSpeed(w.t0, w.t1)) return;
  }
}

// All walks up to t, in time order: always the one whose segment ends first steps, so the
// others' segments covering that moment are known to its speed check. The order depends only on
// the seed, not on the times sampled.
void IdleSynthesizer::Advance(double t) {
  for (const Walk& w : walks_)
    if (t < w.t0) {
      Restart();  // backwards: replay from the seed
      break;
    }
  for (;;) {
    int first = -1;
    for (int i = 0; i < model_->component_count(); ++i)
      if (t > walks_[i].t1 && (first < 0 || walks_[i].t1 < walks_[first].t1)) first = i;
    if (first < 0) return;
    Step(first, true);
  }
}

const Eigen::VectorXd& IdleSynthesizer::Coefficients(double t) {
  if (!std::isfinite(t)) t = 0;
  Advance(t);
  for (int i = 0; i < model_->component_count(); ++i) coefficients_[i] = Value(walks_[i], t);
  return coefficients_;
}

const Eigen::VectorXd& IdleSynthesizer::Posture(double t) {
  ClampedPosture(Coefficients(t), posture_);
  return posture_;
}

void PoseFromPosture(const Skeleton& sk, const LocalPose& rest, const std::vector<int>& joints, int root,
                     const Eigen::VectorXd& p, LocalPose& out) {
  std::copy(rest.rigid.begin(), rest.rigid.end(), out.rigid.begin());
  std::copy(rest.scale.begin(), rest.scale.end(), out.scale.begin());
  const int m = static_cast<int>(joints.size());
  for (int k = 0; k < m; ++k) {
    const int j = joints[k];
    const Eigen::Quaterniond r = sk.rest[j].rotation * ExpMap(p.segment<3>(3 * k));
    out.rigid[j] = DualQuatd::FromRotationTranslation(r, sk.rest[j].translation);
  }
  out.rigid[root] = DualQuatd::FromRotationTranslation(out.rigid[root].Rotation(), sk.rest[root].translation + p.segment<3>(3 * m));
}

bool IdleSynthesizer::Sample(double t, const FrameInputs&, LocalPose& out) {
  if (out.size() != skeleton_->size()) return false;
  PoseFromPosture(*skeleton_, rest_, model_->joints, model_->root, Posture(t), out);
  return true;
}

}  // namespace arview::anim
