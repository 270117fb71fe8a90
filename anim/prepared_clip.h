#pragma once
// A clip laid out for sampling every frame (as ozz-animation's runtime Animation is built
// offline from the raw one): built once (it allocates), then sampled by PreparedSamplingJob
// without allocating and with the same result as SamplingJob (pose.h) to rounding.
//
//   PreparedClip prepared(skeleton, clip);                  // once (ClipSource, ViewAdaptiveBlend)
//   MustRun(PreparedSamplingJob{&prepared, time, /*loop=*/true, &pose}, "where");   // per frame
//
// What sampling no longer repeats every frame:
//   - the key search: channels that share their key times (in the assets here, nearly all of a
//     clip's channels share one or two timelines) are searched once per timeline, not once per
//     channel;
//   - slerp's acos and sin(θ): the angle between each pair of neighbouring rotation keys, its
//     sine and the sign that takes the short way are stored per pair, and sin(fθ), sin((1−f)θ)
//     come from their Taylor series (taylor_trig.h; θ ≤ π/2 on the short way) instead of libm;
//   - channels with one key or none (the rest value) are constants, and a joint whose rotation
//     and translation are both constant has its dual quaternion stored.
// The clip's morph target weight tracks are kept as they are and sampled as SamplingJob does
// (morph.h), into the output's weights when it has them.

#include "anim/pose.h"

#include <span>
#include <vector>

namespace arview::anim {

class PreparedClip {
 public:
  // Samples `joints` of `clip` (empty: every joint); PreparedSamplingJob writes only those and
  // leaves the others of its output as they are. `nlerp` as SamplingJob's. Throws Error when the
  // clip does not fit the skeleton or a joint index is out of range.
  PreparedClip(const Skeleton& skeleton, const Clip& clip, bool nlerp = false, std::span<const int> joints = {});

  double duration() const { return duration_; }
  int joint_count() const { return joint_count_; }  // the skeleton's, the output's size
  std::span<const int> joints() const { return joints_; }
  int timeline_count() const { return static_cast<int>(timelines_.size()); }

 private:
  friend struct PreparedSamplingJob;
  struct Timeline {
    int first = 0, count = 0;  // into times_
  };
  // A channel is either constant (timeline < 0: its value at `first`) or keyed on a timeline
  // with its keys from `first` on (one per time of the timeline).
  struct Channel {
    int timeline = -1;
    int first = 0;
  };
  struct JointPlan {
    int joint = 0;
    Channel rotation, translation, scale;
    int rigid = -1;  // ≥ 0: rotation and translation constant, the dual quaternion at rigids_[rigid]
  };
  // Per pair of neighbouring rotation keys (a, b): the slerp weights are
  // sin((1−f)θ)·inv_sin and sin(fθ)·inv_sin·sign; θ = 0 means linear weights (1−f, f·sign), as
  // Eigen's slerp does for nearly equal keys and as nlerp does always.
  struct RotationPair {
    double theta = 0;
    double inv_sin = 0;
    double sign = 1;
  };

  double duration_ = 0;
  int joint_count_ = 0;
  std::vector<int> joints_;
  std::vector<JointPlan> plan_;
  std::vector<Timeline> timelines_;
  std::vector<double> times_;
  std::vector<Eigen::Quaterniond> rotations_;  // keys and constants
  std::vector<RotationPair> pairs_;            // parallel to rotations_ (the pair starting at that key)
  std::vector<Eigen::Vector3d> vectors_;       // translation and scale keys and constants
  std::vector<DualQuatd> rigids_;
  int morph_target_count_ = 0;
  std::vector<WeightTrack> weight_tracks_;
};

struct PreparedSamplingJob {
  const PreparedClip* clip = nullptr;
  double time = 0;
  bool loop = true;  // wrap time into [0, duration); otherwise clamp
  LocalPose* output = nullptr;

  bool Validate() const;
  [[nodiscard]] bool Run() const;
};

}  // namespace arview::anim
