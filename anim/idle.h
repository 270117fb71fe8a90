#pragma once
// Idle motion (thesis chapter 3, docs/method.md §3): small posture variations synthesised on the
// principal components of standing postures, so that joints vary together as in the data.
//
// A posture is a vector: per animated joint the exponential map of its rotation relative to the
// character's rest rotation (3 values), then the root's translation offset (3 values). The
// model (learned by anim_authoring/idle_learning.h from motion capture mapped onto the
// character, or from its own clips) holds the mean posture, the first principal components
// and their eigenvalues, and per component the extrema of the training signal — (time since
// the previous extremum, value) pairs — clustered with k-means, with the transition counts
// between clusters of consecutive extrema. Synthesis walks each component's cluster chain
// (seeded), draws each next extremum from the recorded members of the chosen cluster (no
// invented values) that lie on the other side of the current one (maxima and minima
// alternate, as in the signal: no plateau from drawing the same value twice), and joins
// consecutive extrema with the recorded segment that ended at the drawn extremum: its own
// duration and its own shape (where it rose fast, where it dwelt), scaled from its recorded
// swing to the new one, and stretched in time when the new swing is larger, so that it is never
// faster than it was recorded. A cosine (zero velocity at both ends) is the fallback where no
// shape was recorded. The posture is the mean plus the components, each value clamped to the
// training data's range.
//
// The components are walked independently, as the thesis does, so at moments their speeds add
// up where the data's dependent ones did not. Each new segment is therefore also stretched in
// time until the posture it produces together with the other components' current segments
// (all of them, reconstructed and clamped as rendered) turns no joint faster than the data's
// own 99th percentile of per-frame fastest-joint speed (IdleModel::speed_limit, measured on the
// training postures at its frame step). The walks step in time order (always the component
// whose segment ends first), so when one steps every other's segment covering that moment is
// known; a component beyond its drawn segment is taken as holding its end extremum (speed 0
// there, as at every extremum), and is checked in turn when it steps.
//
//   IdleSynthesizer idle(skeleton, model, /*seed=*/7);
//   if (!idle.Sample(t, {}, pose)) ...                 // unbounded, deterministic in (seed, t)

#include "anim/blendable.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <random>
#include <vector>

namespace arview::anim {

struct IdleModel {
  std::vector<int> joints;            // character joints whose rotations vary
  int root = 0;                       // the joint whose translation varies
  Eigen::VectorXd mean;               // 3·joints.size() + 3
  Eigen::MatrixXd components;         // dims × m, orthonormal columns
  Eigen::VectorXd eigenvalues;        // m, decreasing
  Eigen::VectorXd min, max;           // per dimension, over the training postures
  struct Extremum {
    double dt = 0;     // seconds since the previous extremum
    double value = 0;  // the component's value there
    double rise = 0;   // value − the previous extremum's value (its sign: a maximum or a minimum)
    // The recorded segment from the previous extremum to this one, normalised: (x − previous) /
    // rise at evenly spaced times, 0 first and 1 last. Synthesis joins two extrema with the
    // shape of the segment that was recorded ending at the drawn one. Empty: a cosine.
    std::vector<double> shape;
  };
  struct ComponentChain {
    std::vector<std::vector<Extremum>> clusters;  // recorded extrema, by k-means cluster
    std::vector<std::vector<double>> transitions; // counts, cluster → next cluster
    std::vector<double> frequency;                // cluster sizes (for rows without transitions)
  };
  std::vector<ComponentChain> chains;  // one per component
  double training_seconds = 0;
  int training_frames = 0;
  // The training postures' fastest joint per frame step (rad/s), its 99th percentile, and the
  // step it was measured at (s). No limit when 0.
  double speed_limit = 0;
  double speed_step = 1.0 / 30;

  int dims() const { return static_cast<int>(mean.size()); }
  int component_count() const { return static_cast<int>(eigenvalues.size()); }
  // Throws Error when sizes disagree or a chain is empty.
  void Check(int skeleton_joints) const;
};

// A posture vector (IdleModel's layout) as a pose: the skeleton's rest pose `rest`, each of
// `joints` turned from its rest rotation by the exponential map of its three values, and `root`
// moved from its rest translation by the last three. `out` has the skeleton's size; no allocation.
void PoseFromPosture(const Skeleton& skeleton, const LocalPose& rest, const std::vector<int>& joints, int root,
                     const Eigen::VectorXd& posture, LocalPose& out);

class IdleSynthesizer : public Blendable {
 public:
  IdleSynthesizer(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<const IdleModel> model, std::uint64_t seed);

  double Duration() const override { return kUnbounded; }
  // Time runs forward: sampling earlier than the chains' window restarts them from the seed
  // and walks forward again (so the stream is a function of (seed, t)).
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return skeleton_->size(); }

  // The component values at t (after Sample or Coefficients(t)).
  const Eigen::VectorXd& Coefficients(double t);
  const Eigen::VectorXd& Posture(double t);  // clamped posture vector at t
  const IdleModel& model() const { return *model_; }

 private:
  struct Walk {
    std::mt19937_64 rng;
    int cluster = 0;
    double t0 = 0, v0 = 0, t1 = 0, v1 = 0;  // the segment [t0, t1] between two extrema
    const std::vector<double>* shape = nullptr;  // its recorded shape (null or empty: cosine)
  };
  static double Value(const Walk& w, double t);  // the walk's component value at t
  void Restart();
  void Advance(double t);
  void Step(int component, bool limit_speed);
  void KeepWithinDataSpeed(int component);
  // Whether every joint's angular speed (rad/s) over chords of one speed_step starting every half
  // step from `from` − half a step to `to` − half a step, at the walks' current segments, is at
  // most the model's speed_limit (the posture reconstructed, clamped and each joint's angle
  // change measured as rendered; see WithinDataSpeed in idle.cpp for how it is kept cheap).
  bool WithinDataSpeed(double from, double to);
  // The clamped posture at grid point n of the current check (from grid_coefficients_, which
  // hold the last three grid points' values), computed once per grid point.
  const Eigen::VectorXd& GridPosture(int n);
  // mean + components · coefficients, each value clamped to the training data's range.
  void ClampedPosture(const Eigen::VectorXd& coefficients, Eigen::VectorXd& posture) const;

  std::shared_ptr<const Skeleton> skeleton_;
  std::shared_ptr<const IdleModel> model_;
  std::uint64_t seed_;
  std::vector<Walk> walks_;
  Eigen::VectorXd coefficients_, posture_;
  LocalPose rest_;  // the skeleton's rest pose: the joints the model does not vary
  // The speed check's bounds, from the model: per joint and component the norm of the
  // component's 3-row block of that joint's rotation, and per component the largest of them.
  Eigen::MatrixXd joint_reach_;      // components × joints
  Eigen::VectorXd component_reach_;  // components
  // Scratch for the speed check (sized once: no allocation per frame).
  Eigen::VectorXd grid_coefficients_[3];  // the component values at the last three grid points
  Eigen::VectorXd chord_change_;          // their change over the chord, absolute values
  Eigen::VectorXd grid_postures_[3];      // clamped postures at grid points grid_posture_at_
  int grid_posture_at_[3] = {-1, -1, -1};
};

}  // namespace arview::anim
