#pragma once
// Blendable objects of the MIRAnim engine (thesis §4.2.1, docs/method.md §2): anything that maps a
// time to a pose of one skeleton, with or without a fixed duration. Clips, static poses, the
// view-adaptive blend (view_adaptive.h), the idle synthesizer (idle.h) and schedules
// (schedule.h) are blendable; modifiers wrap a blendable and are blendable again.
//
//   auto walk = std::make_shared<ClipSource>(skeleton, clip);
//   auto twice = std::make_shared<Loop>(walk, 2);                 // 2 × walk's length
//   auto slow = std::make_shared<TimeStretch>(twice, 5.0);         // ... played over 5 s
//   if (!slow->Sample(t, inputs, pose)) ...                        // per frame, no allocation
//
// Objects are built once (allocation allowed) and sampled every frame without allocating; they
// may keep scratch buffers, so one object is sampled by one thread at a time.

#include "anim/pose.h"
#include "anim/prepared_clip.h"

#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace arview::anim {

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// What the world tells the animation each frame.
struct FrameInputs {
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // unit, character frame (view-adaptive)
  double distance = -1;                                   // viewer to character, metres; < 0 unknown
  bool tracking = true;                                   // whether the viewer is tracked
  // The viewer's eyes (the camera centre) in model space, for gaze (anim/gaze.h); not finite
  // when unknown.
  Eigen::Vector3d viewer = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The idle's pause length (thesis §4.1.2, Eq. 4.2): the factor on the random part of each rest
  // between balance shifts, p_o' = (α − activation)·β·p_o. 1: the data's pauses; 0: the shortest
  // (high activation); 2: the calmest. Set from the character's emotion (dialogue::PauseOffsetScale).
  double pause_offset_scale = 1;
};

class Blendable {
 public:
  virtual ~Blendable() = default;
  // Seconds, or kUnbounded (an idle synthesizer, a view-adaptive blend, a static pose).
  virtual double Duration() const = 0;
  // The pose at local time t ≥ 0 (t past Duration(): the last frame). `out` has the skeleton's
  // joint count. False when the inputs do not fit (a bug in how the object was built).
  [[nodiscard]] virtual bool Sample(double t, const FrameInputs& inputs, LocalPose& out) = 0;
  virtual int joint_count() const = 0;
};

using BlendablePtr = std::shared_ptr<Blendable>;

// A clip of the skeleton, played once (Loop repeats it). Holds the clip by shared pointer (it
// may alias into a Character).
class ClipSource : public Blendable {
 public:
  ClipSource(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<const Clip> clip, bool nlerp = false);
  double Duration() const override { return clip_->duration; }
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return skeleton_->size(); }
  const Clip& clip() const { return *clip_; }

 private:
  std::shared_ptr<const Skeleton> skeleton_;
  std::shared_ptr<const Clip> clip_;
  PreparedClip prepared_;
};

// One pose held (thesis: a single key-frame animated by a curve). Unbounded unless given a
// duration.
class StaticPose : public Blendable {
 public:
  explicit StaticPose(LocalPose pose, double duration = kUnbounded);
  double Duration() const override { return duration_; }
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return pose_.size(); }

 private:
  LocalPose pose_;
  double duration_;
};

// Plays the inner object over `duration` seconds (slower or faster); needs a bounded inner.
class TimeStretch : public Blendable {
 public:
  TimeStretch(BlendablePtr inner, double duration);
  double Duration() const override { return duration_; }
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return inner_->joint_count(); }

 private:
  BlendablePtr inner_;
  double duration_;
};

// Repeats a bounded inner object `count` times, or forever (count ≤ 0).
class Loop : public Blendable {
 public:
  explicit Loop(BlendablePtr inner, int count = 0);
  double Duration() const override;
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return inner_->joint_count(); }

 private:
  BlendablePtr inner_;
  int count_;
};

// The part [from, to) of the inner object, as an object of length to − from.
class Window : public Blendable {
 public:
  Window(BlendablePtr inner, double from, double to);
  double Duration() const override { return to_ - from_; }
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return inner_->joint_count(); }

 private:
  BlendablePtr inner_;
  double from_, to_;
};

// Left/right mirror (thesis: "flip"): each joint takes its partner's motion (partners by name:
// Left↔Right, _L↔_R, ...), reflected across the character's sagittal plane (normal
// `lateral` = up × forward in model space). Done in model space against the rest pose so that
// it holds for rigs whose left and right joint frames are not mirror images: at rest the mirror
// returns the rest pose. Morph target weights are mirrored by name too: each target takes its
// partner's weight (MirrorTargetPartners).
class Mirror : public Blendable {
 public:
  Mirror(BlendablePtr inner, std::shared_ptr<const Skeleton> skeleton, const Eigen::Vector3d& lateral = Eigen::Vector3d::UnitX());
  double Duration() const override { return inner_->Duration(); }
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return inner_->joint_count(); }
  // partner[j]: the joint whose motion j takes (itself for centre joints).
  const std::vector<int>& partners() const { return partner_; }
  const std::vector<int>& target_partners() const { return target_partner_; }

 private:
  BlendablePtr inner_;
  std::shared_ptr<const Skeleton> skeleton_;
  Eigen::Vector3d n_;
  std::vector<int> partner_;
  std::vector<int> target_partner_;  // per morph target, the one whose weight it takes
  std::vector<Eigen::Quaterniond> correction_;  // per joint: mirrored rest → rest
  LocalPose source_;
  std::vector<Eigen::Quaterniond> model_rot_, mirrored_rot_;
  std::vector<Eigen::Vector3d> model_pos_, mirrored_pos_;
};

// Partners by name (Left↔Right, left↔right, _L↔_R, .L↔.R, L_↔R_, CMU's LThumb↔RThumb); joints
// without a partner map to themselves.
std::vector<int> MirrorPartners(const Skeleton& skeleton);
// The same for the morph targets by their names (eyeBlinkLeft↔eyeBlinkRight, mouthSmileLeft↔
// mouthSmileRight); targets without a partner (jawOpen, the visemes) map to themselves.
std::vector<int> MirrorTargetPartners(const Skeleton& skeleton);

// A rigid transform applied to the root joints (turn or move the whole animation).
class GlobalTransform : public Blendable {
 public:
  GlobalTransform(BlendablePtr inner, std::shared_ptr<const Skeleton> skeleton, const DualQuatd& transform);
  double Duration() const override { return inner_->Duration(); }
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return inner_->joint_count(); }

 private:
  BlendablePtr inner_;
  std::shared_ptr<const Skeleton> skeleton_;
  DualQuatd transform_;  // in model space (before root_parent)
};

}  // namespace arview::anim
