#pragma once
// The blending schedule and frame blender of the MIRAnim engine (thesis §4.2.2, docs/method.md §2).
//
//   Schedule s(skeleton, {BlendMethod::kDlb});
//   int idle = s.Add({idle_synth, {}, 0.0, /*keep_rendering=*/true, "idle"});
//   BlendingParams p; p.curves = {Curve::CosineFade(0.2, 0.2)}; p.masks = {torso};
//   int wave = s.Add({wave_clip, p, 1.0, false, "wave"});    // starts at t = 1 s
//   s.Retime(wave, 3.0);  s.Remove(idle);                      // while it runs
//   if (!s.Sample(t, inputs, pose)) ...                        // per frame, no allocation
//
// The frame blender mixes, joint by joint, the local transforms of every action active at t
// with weights w_a,j(t) = gain_a · curves_a(t) · masks_a(j).
//   - Within a layer (Action::layer) the weights are normalised over its actions: the thesis's
//     weighted blend (appendix C example 3: a torso-masked gesture at 1 over an idle at 0.1 on
//     the torso gives the torso 1/1.1 of the gesture).
//   - Layer 0 sits on the rest pose as in ozz's blending job: when a joint's total weight is
//     below `rest_threshold` the rest pose makes up the difference, so a joint no action covers
//     holds the rest pose and fades into and out of it continuously.
//   - Each higher layer overrides what is below it in proportion to its total weight W_j (the
//     result below enters with weight max(0, 1 − W_j)): "idle underneath, view-adaptive on top"
//     is the view layer at 1, and fading it to 0 leaves the idle.
// Rotations and translations have their own masks: where they agree the joint's dual
// quaternions are blended with DLB or DIB; where they differ, rotation (sign-aligned normalised
// sum) and translation (weighted mean) are blended apart. A joint with exactly one contributor
// takes its transform unchanged (a masked layer leaves the others exactly as they were).
// Morph target weights (the face, morph.h) blend the same way, as scalars, over the actions whose
// object keyed them (LocalPose::morph_keyed: a clip with weight tracks) with their time weights
// (joint masks do not apply): normalised within a layer, the rest (every weight 0) filling layer 0
// up to the threshold, each higher layer over what is below in proportion to its total weight.
//
// A schedule is blendable, so schedules nest (an action's object may be a schedule). Its
// duration is the end of its last bounded action, or unbounded when an action keeps rendering
// or is unbounded. Edits (Add/Remove/Retime/FadeGain/SetLiveWeight) happen between frames; they may allocate
// (copying the action's parameters) but never grow the schedule past the capacity given at
// construction (then Add throws); Sample never allocates.

#include "anim/blendable.h"
#include "anim/blending_params.h"

#include <string>
#include <vector>

namespace arview::anim {

struct Action {
  BlendablePtr object;
  BlendingParams params;
  double start = 0;             // schedule time at which it starts (seconds)
  bool keep_rendering = false;  // past its end it holds its last frame (thesis: "alwaysrender")
  std::string name;
  int layer = 0;                // 0: on the rest pose; higher: over the layers below
};

struct FrameBlenderOptions {
  BlendMethod method = BlendMethod::kDlb;
  DibOptions<double> dib;
  double rest_threshold = 0.1;  // ozz::animation::BlendingJob's default threshold
};

class Schedule : public Blendable {
 public:
  static constexpr int kDefaultCapacity = 16;
  Schedule(std::shared_ptr<const Skeleton> skeleton, const FrameBlenderOptions& options = {},
           int capacity = kDefaultCapacity);

  // Returns the action's id (stable until removed). Throws Error when the object's joint count
  // is not the skeleton's, a curve does not fit the object's length, a mask has the wrong
  // size, or the schedule is full.
  int Add(Action action);
  // False when no action has this id.
  bool Remove(int id);
  bool Retime(int id, double start);
  // A run-time fade of the action's gain from its current value to `target` over `seconds`
  // (cosine), starting at schedule time `now`: how the appliance fades the view-adaptive layer
  // out on tracking loss and back on relocalization without re-creating it.
  bool FadeGain(int id, double target, double now, double seconds);
  // The gain at schedule time t (1 unless faded).
  double Gain(int id, double t) const;
  // A multiplier of the action's weight set between frames (e.g. from the viewer's distance);
  // 1 by default. False for an unknown id or a negative or non-finite weight.
  bool SetLiveWeight(int id, double weight);
  const Action* Find(int id) const;
  int FindByName(const std::string& name) const;  // −1 if none
  int action_count() const { return static_cast<int>(slots_.size()) - free_count(); }

  double Duration() const override;
  bool Sample(double t, const FrameInputs& inputs, LocalPose& out) override;
  int joint_count() const override { return skeleton_->size(); }

  // Of the last Sample: the summed time weight of the actions that contributed, per id.
  double last_weight(int id) const;
  bool last_converged() const { return converged_; }

 private:
  struct GainFade {
    double from = 1, to = 1, start = 0, seconds = 0;
    double At(double t) const;
  };
  struct Slot {
    bool used = false;
    Action action;
    GainFade gain;
    double live = 1;
    LocalPose pose;     // this frame's sample
    double weight = 0;  // this frame's time weight (0: inactive)
    double scaling = 1;
    double length = 0;  // cached object duration
    // The action's masks multiplied out per joint (BlendingParams::MaskRotation/Translation),
    // filled by Add; sized with the schedule, so that adding allocates no more than the action.
    std::vector<double> mask_rotation, mask_translation;
  };
  int free_count() const;
  void Blend(LocalPose& out);
  void BlendMorph(LocalPose& out) const;

  std::shared_ptr<const Skeleton> skeleton_;
  FrameBlenderOptions options_;
  std::vector<Slot> slots_;
  std::vector<int> active_;  // slot indices active this frame (capacity reserved)
  LocalPose rest_;
  bool converged_ = true;
};

}  // namespace arview::anim
