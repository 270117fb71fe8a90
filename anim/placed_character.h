#pragma once
// A character standing in the map, as the per-frame path sees it: the loaded character, where it
// stands (Placement), the view-adaptive blend over its keys, and the chains its generated keys
// turn. anim_authoring builds one from a scene (anim_authoring/character_builder.h); the
// pipeline, the renderer and the overlay use only this.
//
//   const Eigen::Vector3d v = placed.placement().ViewpointFromCamera(C);
//   const AnimatorFrame& f = placed.Update(v, time_seconds);   // the view-adaptive blend alone
//   f.skinning_matrices / f.skinning_dual_quats → the renderer; f.key_weights → the overlay
//
// Update is the blend without a schedule (`arview anim weights`, the tests); a live character is
// animated by its Animator (anim/animator.h), which plays view_adaptive() as one of its actions.

#include <Eigen/Core>

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "anim/chains.h"
#include "anim/character.h"
#include "anim/gaze.h"
#include "anim/placement.h"
#include "anim/view_adaptive.h"

namespace arview::anim {

// What a PlacedCharacter is made of; anim_authoring fills it in.
struct PlacedCharacterParts {
  std::shared_ptr<const Character> character;
  Placement placement;
  std::shared_ptr<ViewAdaptiveBlend> blend;
  std::string name;
  std::string where;                     // "scene.yaml:3", for messages
  std::vector<Eigen::Vector3d> key_viewpoints;  // unit, character frame, as the scene gives them
  std::vector<std::string> key_labels;   // what each key plays ("Survey", "lookat", ...), for the overlay
  LookAtChain lookat;                    // empty joints without look-at keys
  ArmChain arm;                          // joints −1 without gesture keys
  std::optional<GazeSetup> gaze;         // eyes and lids toward the viewer (none without eyes)
};

class PlacedCharacter {
 public:
  explicit PlacedCharacter(PlacedCharacterParts parts);

  const Character& character() const { return *parts_.character; }
  std::shared_ptr<const Character> shared_character() const { return parts_.character; }
  std::shared_ptr<const Skeleton> shared_skeleton() const { return {parts_.character, &parts_.character->skeleton}; }
  const Placement& placement() const { return parts_.placement; }
  // Moves the character (a first run stands it in front of the first view it is seen from). The
  // renderer keeps its own copy: ArRenderer::MoveCharacter.
  void SetPlacement(const Placement& placement) { parts_.placement = placement; }
  const std::string& name() const { return parts_.name; }
  const std::string& where() const { return parts_.where; }
  const ViewSphere& view_sphere() const { return parts_.blend->view_sphere(); }
  const std::vector<Eigen::Vector3d>& key_viewpoints() const { return parts_.key_viewpoints; }
  const std::vector<std::string>& key_labels() const { return parts_.key_labels; }
  // One clip per key (shared between keys that name the same clip).
  const Clip& key_clip(int key) const { return *parts_.blend->key(key).clip; }
  // The look-at chain of the generated keys (empty joints if none).
  const LookAtChain& lookat_chain() const { return parts_.lookat; }
  // The arm chain of the gesture keys (joints −1 if none).
  const ArmChain& arm_chain() const { return parts_.arm; }
  // The runtime blend, to schedule it as an action (anim/schedule.h).
  std::shared_ptr<ViewAdaptiveBlend> view_adaptive() const { return parts_.blend; }

  // Weights for `viewpoint` (character frame), then every key clip sampled at `time_seconds`,
  // blended, and converted to skinning transforms. Valid until the next call; no allocation.
  // With gaze (parts.gaze), the eyes turn toward `viewer` (the camera centre in model space,
  // Placement::MapToModel) as the Animator turns them; not finite: they look ahead.
  const AnimatorFrame& Update(const Eigen::Vector3d& viewpoint, double time_seconds,
                              const Eigen::Vector3d& viewer = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  // The gaze setup (none for a character without eyes or with gaze off).
  const std::optional<GazeSetup>& gaze() const { return parts_.gaze; }

 private:
  PlacedCharacterParts parts_;
  FrameBuffers buffers_;
  std::optional<Gaze> gaze_;
  AnimatorFrame frame_;
};

}  // namespace arview::anim
