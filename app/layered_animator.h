#pragma once
// The character's animation as the appliance drives it (PAPERS.md §2): the view-adaptive blend
// (anim::AnimatedCharacter) runs over an idle layer, the base clip. While the tracker follows
// the camera, the view-adaptive layer has full weight. When tracking is lost the character
// holds its last viewpoint for `hold_seconds` (time keeps running: no freeze), then fades to
// the idle layer over `fade_seconds`; when the tracker relocalizes it fades back. The fade mixes
// model-space joint transforms (translation and scale linearly, rotation by slerp), so no joint
// jumps from one frame to the next.

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "anim/pose.h"
#include "anim/scene.h"

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
  double idle_weight = 0;               // 0: fully view-adaptive, 1: fully the base clip
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // the one used (character frame)
};

class LayeredAnimator {
 public:
  // `character` must outlive the animator. The idle layer is `idle_clip` of the asset, or the
  // scene's look-at base clip ("rest": the rest pose), or the asset's first clip, or the rest pose.
  explicit LayeredAnimator(anim::AnimatedCharacter& character, const std::string& idle_clip = "",
                           const FadeOptions& options = {});

  // `camera_center` is the (smoothed) camera centre in map coordinates, or nothing when the
  // tracker lost the frame. `time` is the video time in seconds (monotonic).
  const AnimatedFrame& Update(const std::optional<Eigen::Vector3d>& camera_center, double time);

  const anim::Clip* idle_clip() const { return idle_; }
  const anim::AnimatedCharacter& character() const { return character_; }

 private:
  void MixWithIdle(std::span<const Eigen::Matrix4d> adaptive, double idle_weight);

  anim::AnimatedCharacter& character_;
  const anim::Clip* idle_ = nullptr;
  FadeOptions options_;
  Eigen::Vector3d last_viewpoint_ = Eigen::Vector3d::UnitZ();
  std::optional<double> lost_since_;
  double idle_weight_ = 0;
  std::optional<double> last_time_;

  anim::LocalPose idle_pose_;
  std::vector<Eigen::Matrix4d> idle_model_, mixed_model_;
  std::vector<Eigen::Matrix4f> skin_;
  std::vector<anim::DualQuatf> skin_dq_;
  AnimatedFrame frame_;
};

}  // namespace arview::app
