#pragma once
// A character's animation as the appliance (and `arview view`) drives it: one schedule per
// character (idle underneath, the view-adaptive action on top, scene actions), plus what the
// world decides each frame:
//   - tracking: when the viewer is lost the view-adaptive action holds its last viewpoint for
//     `hold_seconds`, then fades out (cosine, `fade_seconds`) to what is below it (the idle);
//     on relocalization it fades back in. Time keeps running: the character never freezes.
//   - distance: actions triggered when the viewer comes within `near` metres (re-armed beyond
//     `far`: hysteresis), and action weights as piecewise-linear functions of the distance.
// Then local-to-model and skinning, once.
//
//   Animator animator(skeleton, schedule, options);     // anim_authoring builds these from a scene
//   FrameInputs in{viewpoint, distance_m, tracking_ok};
//   const AnimatorFrame& f = animator.Update(time_s, in);   // per frame, no allocation
//   f.skinning_matrices / f.skinning_dual_quats → the renderer
//
// With gaze (AnimatorOptions::gaze), the eyes and lids are posed after the schedule, from the
// head the look-at chain placed, toward FrameInputs::viewer (anim/gaze.h).
//
// With a face (AnimatorOptions::face), a speech layer hands Update the frame's FaceTrack: the
// mouth's targets and the Jaw joint follow the visemes (anim/face.h), gaze switches to its
// talking statistics while the character talks, and a blink overrides the lid targets.
//
// Update allocates only when a distance trigger fires (it adds an action to the schedule); Play
// (a line's gesture or expression) allocates as it adds its action.

#include "anim/face.h"
#include "anim/gaze.h"
#include "anim/schedule.h"
#include "anim/view_adaptive.h"

#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace arview::anim {

struct DistanceTrigger {
  double near = 1.5;  // fires when the distance drops to this (metres) while armed
  double far = 2.0;   // re-arms when it rises above this (far > near)
  Action action;      // added to the schedule when it fires; action.start is relative to then
};

struct DistanceWeight {
  std::string action;                          // by name
  std::vector<std::pair<double, double>> points;  // (distance m, weight), distances increasing
  double At(double distance) const;            // clamped at the ends
};

struct AnimatorOptions {
  std::string view_action = "view";  // the action faded on tracking loss ("" or absent: none)
  double hold_seconds = 0.5;
  double fade_seconds = 1.0;
  std::vector<DistanceTrigger> triggers;
  std::vector<DistanceWeight> distance_weights;
  // Eyes and lids posed after the schedule (anim/gaze.h); nothing for a character without eyes.
  std::optional<GazeSetup> gaze;
  // The face speech drives (anim/face.h); nothing for a character without the 15 viseme targets.
  std::optional<FaceRig> face;
};

// The one description of an animated frame, from the animator (or PlacedCharacter::Update) to the
// renderer, the overlay and the statistics.
struct AnimatorFrame {
  std::span<const Eigen::Matrix4f> skinning_matrices;
  std::span<const DualQuatf> skinning_dual_quats;
  std::span<const Eigen::Matrix4d> model;
  std::span<const LocalPose> local;           // one element: the blended local pose
  std::span<const double> key_weights;        // of the view-adaptive blend (empty without one)
  double view_gain = 0;                       // the view-adaptive action's gain now (0..1)
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // the one used (held while lost)
  bool converged = true;                      // DIB converged on every joint
  int max_iterations = 0;                     // DIB, the worst joint (PlacedCharacter::Update)
  int triggered = 0;                          // distance triggers fired this frame
  // One weight per morph target (Skeleton::morph_targets; empty without targets): the playing
  // clips' weight tracks blended, then whatever a face layer set (Animator::SetMorphWeight).
  std::span<const float> morph_weights;
  GazeFrame gaze;                             // eyes on the viewer, blinking (Animator with gaze)
  FaceFrame face;                             // speech on the face (Animator with a face)

  // The weight of the layers below the view-adaptive action (the idle): 0 while the viewer is
  // tracked, 1 once the view-adaptive action has faded out (or where there is none).
  double idle_weight() const { return 1.0 - view_gain; }
};

// The buffers an animated frame is built in, sized once for a skeleton: the one blended local
// pose, its model-space joints and skinning transforms. Finish() is the step the Animator and
// PlacedCharacter::Update both end with.
struct FrameBuffers {
  FrameBuffers() = default;
  explicit FrameBuffers(const Skeleton& skeleton);
  // local[0] to model space, then to skinning transforms; `frame`'s pose spans point at them.
  // The two names label a failed job's error.
  void Finish(const Skeleton& skeleton, AnimatorFrame& frame, const char* local_to_model, const char* skinning);

  std::vector<LocalPose> local;  // one
  std::vector<Eigen::Matrix4d> model;
  std::vector<Eigen::Matrix4f> skin;
  std::vector<DualQuatf> skin_dq;
};

class Animator {
 public:
  // `view` is the view-adaptive blend the schedule's view action plays (for its key weights), or
  // nullptr. Throws Error when a distance weight names an action the schedule lacks, or a
  // trigger's far is not beyond its near.
  Animator(std::shared_ptr<const Skeleton> skeleton, std::shared_ptr<Schedule> schedule, AnimatorOptions options = {},
           std::shared_ptr<const ViewAdaptiveBlend> view = nullptr);

  // `time` in seconds, monotonic (a jump backwards restarts the tracking-loss state). `face`:
  // what speech does to the face this frame (nullptr: nothing, the character is silent).
  const AnimatorFrame& Update(double time, const FrameInputs& inputs, const FaceTrack* face = nullptr);

  // Adds `action` to the schedule (its start in schedule time), to leave it once it has ended, as
  // a triggered action does: a spoken line's gesture or expression. Returns its id; throws Error
  // when the schedule is full or the action does not fit it.
  int Play(Action action);
  // The eyes fixate the viewer from schedule time `from` until `until` (a line's
  // <gaze at="viewer"/>); nothing for a character without gaze.
  void HoldGazeOnViewer(double from, double until);

  // A face layer's write, after Update and before the frame is drawn: target `target`'s weight
  // in the frame Update returned (the next Update starts again from the clips). False, and
  // nothing written, for a target out of range or a non-finite weight. Never allocates.
  bool SetMorphWeight(int target, float weight);

  Schedule& schedule() { return *schedule_; }
  const Skeleton& skeleton() const { return *skeleton_; }
  int view_action_id() const { return view_id_; }

 private:
  void Track(double time, bool tracking);
  void Distance(double time, double distance);
  void Look(double time, const Eigen::Vector3d* viewer);  // poses the eyes and lids (gaze_)
  void RemoveEndedActions(double time);                  // played and triggered actions past their end

  std::shared_ptr<const Skeleton> skeleton_;
  std::shared_ptr<Schedule> schedule_;
  AnimatorOptions options_;
  std::shared_ptr<const ViewAdaptiveBlend> view_;
  int view_id_ = -1;
  std::vector<int> weight_ids_;      // per distance weight
  std::vector<bool> armed_;          // per trigger
  std::vector<int> fired_ids_;       // actions added by triggers and Play, removed once they end
  std::optional<double> last_time_;
  std::optional<double> lost_since_;
  bool fading_out_ = false;
  Eigen::Vector3d viewpoint_ = Eigen::Vector3d::UnitZ();
  FrameInputs inputs_;
  Eigen::Vector3d viewer_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());  // held while lost
  std::optional<Gaze> gaze_;
  FrameBuffers buffers_;
  AnimatorFrame frame_;
};

}  // namespace arview::anim
