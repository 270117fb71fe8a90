#pragma once
// The character's animation as the appliance drives it (PAPERS.md §2), on anim/'s MIRAnim
// engine (anim/animator.h): a schedule per character — by default the idle layer underneath
// (the scene's idle synthesizer, or the base clip looped, or the rest pose) and the
// view-adaptive action on top, or the scene's own `schedule:`. While the tracker follows the
// camera the view-adaptive action has full weight. When tracking is lost the character holds its
// last viewpoint for `hold_seconds` (time keeps running: no freeze), then the view-adaptive
// action fades out (cosine, over `fade_seconds`) to the layers below it; when the tracker
// relocalizes it fades back. The fade blends local joint transforms (dual quaternions), so bones
// keep their lengths and no joint jumps. The viewer's distance to the character (map units,
// along the character's floor: the camera's height above it does not count) drives the scene's
// distance triggers and weights.

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "anim_authoring/scene.h"

namespace arview::app {

struct FadeOptions {
  double hold_seconds = 0.5;
  double fade_seconds = 1.0;
};

struct AnimatedFrame {
  std::span<const Eigen::Matrix4f> skinning_matrices;
  std::span<const anim::DualQuatf> skinning_dual_quats;
  std::span<const Eigen::Matrix4d> model;
  std::span<const double> key_weights;  // of the view-adaptive layer
  double idle_weight = 0;               // 0: fully view-adaptive, 1: fully the layers below it
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // the one used (character frame)
  int triggered = 0;                    // distance-triggered actions started this frame
};

class LayeredAnimator {
 public:
  // `character` must outlive the animator. The default schedule's idle layer is `idle_clip` of
  // the asset, or the scene's idle synthesizer, or its look-at base clip ("rest": the rest pose),
  // or the asset's first clip, or the rest pose. `options` override the scene's tracking_loss.
  explicit LayeredAnimator(anim::AnimatedCharacter& character, const std::string& idle_clip = "",
                           const FadeOptions& options = {});

  // `camera_center` is the (smoothed) camera centre in map coordinates, or nothing when the
  // tracker lost the frame. `time` is the video time in seconds (monotonic).
  const AnimatedFrame& Update(const std::optional<Eigen::Vector3d>& camera_center, double time);

  // The clip of the default idle layer, or nullptr (rest pose, idle synthesizer, scene schedule).
  const anim::Clip* idle_clip() const { return idle_; }
  const anim::AnimatedCharacter& character() const { return character_; }
  anim::Animator& animator() { return *animator_; }
  // What the user should be told about the animation built (one line each, for "note: "): a
  // layer the scene asked for that its data cannot support, e.g. balance shifts from a recording
  // without a transition.
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  anim::AnimatedCharacter& character_;
  const anim::Clip* idle_ = nullptr;
  std::unique_ptr<anim::Animator> animator_;
  std::vector<std::string> notes_;
  AnimatedFrame frame_;
};

}  // namespace arview::app
