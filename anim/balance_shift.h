#pragma once
// Balance shifts (thesis §3.3, docs/method.md §3): the idle layer's slow part. A person standing
// rests with the weight on the left foot, on the right, or on both, and now and then shifts it.
// The model (learned by anim_authoring/balance.h from a recording of a person standing, never
// invented) holds, in the idle model's posture layout (idle.h):
//   - the resting postures of each category: the first and last frames of the recorded
//     transitions (the thesis's Q_c);
//   - the recorded transition segments, each from one category to another, frame by frame;
//   - the category transition graph: how often each transition was recorded (its probability is
//     that count over the category's outgoing ones) and, per category, the shortest and longest
//     recorded rest before a transition (dwell times);
//   - the first principal components of the idle PCA with their eigenvalues, for the distance
//     between postures d(p, q) = sqrt(Σ_i λ_i (p_i − q_i)²) over their component values.
//
// Synthesis (seeded, a function of (seed, t) as the idle synthesizer): rest in a category for a
// dwell drawn within its range, holding a resting posture p; draw the next category s by the
// transition probabilities and a resting posture q of s; of the recorded segments from the
// current category to s take the one whose first frame is nearest p and last frame nearest q
// (the thesis's minimal max(d(a_0, p), d(a_e, q))); play it fitted: the offsets p − a_0 and
// q − a_e interpolated linearly along it and added, so it starts at p and ends at q exactly (no
// jump at either end); then rest at q, and so on.
//
// With an idle synthesizer given, its small posture variations (its posture minus its mean) are
// added on top at every moment, as the thesis lays the PC noise over the balance shifts.
//
//   BalanceShifter balance(skeleton, model, /*seed=*/3, idle);   // idle: optional
//   if (!balance.Sample(t, {}, pose)) ...                        // unbounded, no allocation

#include "anim/blendable.h"
#include "anim/idle.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

namespace arview::anim {

// Where a standing person's weight is: over the left foot, between the feet, over the right.
enum class Support { kLeft = 0, kBoth = 1, kRight = 2 };
inline constexpr int kSupports = 3;
const char* SupportName(Support s);

struct BalanceModel {
  std::vector<int> joints;            // the idle model's posture layout: rotating joints ...
  int root = 0;                       // ... and the joint whose translation moves
  Eigen::VectorXd mean;               // the idle PCA: mean posture,
  Eigen::MatrixXd components;         // its first components (dims × m, orthonormal columns)
  Eigen::VectorXd eigenvalues;        // and their eigenvalues (the distance's weights)
  struct Segment {
    Support from = Support::kBoth, to = Support::kBoth;
    std::vector<Eigen::VectorXd> frames;  // postures at `rate`, first and last included
    double rate = 30;
    double recorded_at = 0;               // seconds into its recording (for reports)
    double Seconds() const { return (static_cast<double>(frames.size()) - 1) / rate; }
  };
  std::vector<Segment> segments;
  std::array<std::vector<Eigen::VectorXd>, kSupports> rests;  // resting postures per category
  std::array<std::array<int, kSupports>, kSupports> counts{}; // recorded transitions from → to
  std::array<double, kSupports> dwell_min{}, dwell_max{};    // seconds, per category with transitions out

  int dims() const { return static_cast<int>(mean.size()); }
  // Whether the walk can leave category c (it has a recorded transition to a category it can
  // leave in turn: see anim_authoring/balance.h, which keeps only such categories).
  bool CanLeave(Support c) const;
  double Probability(Support from, Support to) const;
  // d(a, b) = sqrt(Σ_i λ_i (a_i − b_i)²) over the component values of postures a and b.
  double Distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const;
  // Throws Error when sizes disagree, a segment is shorter than two frames, a category that can
  // be left has no resting posture, or the graph has no category that can be left.
  void Check(int skeleton_joints) const;
};

// The recorded segment from `from` to `to` to fit between resting postures p and q: the one with
// the least max(d(a_0, p), d(a_e, q)) (the first such, on ties). −1 when none was recorded.
int ChooseSegment(const BalanceModel& model, Support from, Support to, const Eigen::VectorXd& p, const Eigen::VectorXd& q);

// Segment `a` fitted to start at p and end at q, at fraction u ∈ [0, 1] of it: the recorded
// posture (linear between frames) plus the end offsets interpolated, (p − a_0)(1 − u) + (q − a_e)u.
void FittedPosture(const BalanceModel::Segment& a, const Eigen::VectorXd& p, const Eigen::VectorXd& q, double u,
                   Eigen::VectorXd& out);

class BalanceShifter : public Blendable {
 public:
  // `variations`: an idle synthesizer with the same posture layout whose small variations are
  // added on top (optional).
  BalanceShifter(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<const BalanceModel> model, std::uint64_t seed,
                 std::shared_ptr<IdleSynthesizer> variations = nullptr);

  double Duration() const override { return kUnbounded; }
  // Time runs forward; sampling before the current rest or transition replays from the seed.
  // inputs.pause_offset_scale sets the random part of the rests drawn from then on (a rest under
  // way keeps its length), so the walk is a function of (seed, t) only while the scale holds.
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  // The factor on each rest's random part from now on (FrameInputs::pause_offset_scale; negative
  // or not finite: 1). Sample sets it from its inputs.
  void SetPauseOffsetScale(double scale);
  int joint_count() const override { return skeleton_->size(); }

  // Where the walk is: resting in `from` (segment −1), or in transition `segment` from `from`
  // to `to`, over [t0, t1).
  struct State {
    int segment = -1;
    Support from = Support::kBoth, to = Support::kBoth;
    double t0 = 0, t1 = 0;
  };
  // The balance posture at t, without the small variations (valid until the next call), and the
  // state it is in.
  const Eigen::VectorXd& Posture(double t);
  const State& state() const { return state_; }
  // The resting postures the current state joins: held (rest), or fitted between (transition).
  const Eigen::VectorXd& from_posture() const { return p_; }
  const Eigen::VectorXd& to_posture() const { return q_; }
  const BalanceModel& model() const { return *model_; }

 private:
  void Restart();
  void Advance(double t);
  void NextState();
  const Eigen::VectorXd& DrawRest(Support c);
  double DrawDwell(Support c);

  std::shared_ptr<const Skeleton> skeleton_;
  std::shared_ptr<const BalanceModel> model_;
  std::uint64_t seed_;
  std::shared_ptr<IdleSynthesizer> variations_;
  std::mt19937_64 rng_;
  double pause_offset_scale_ = 1;
  State state_;
  Eigen::VectorXd p_, q_;       // resting postures: the current (rest) or the two joined (transition)
  Eigen::VectorXd posture_;     // scratch, sized once
  LocalPose rest_;
};

}  // namespace arview::anim
