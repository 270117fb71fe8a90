#pragma once
// Authoring of gesture keys: a look-at key (lookat.h) with one arm turned on top of it so that
// the hand points or reaches along the key's viewpoint — the paper's character that "turns
// around, looks at the user and gestures toward the user". Like look-at keys, a gesture key is
// a clip blended like any key, and several keys may share a viewpoint.
//
// The arm is a two-bone chain (upper arm → forearm → hand) solved analytically per sample:
//   point  the forearm lies along the viewpoint direction; the upper arm bends away from it by
//          a small elbow angle (`point_bend_deg`), the elbow dropping toward its pole.
//   reach  the hand is placed along the viewpoint direction from the shoulder at the distance
//          that bends the elbow by `reach_bend_deg` (law of cosines), the elbow toward its pole.
// Joint limits: the elbow bend stays within [elbow_min_deg, elbow_max_deg]; the upper arm stays
// in a cone of `shoulder_cone_deg` about the direction halfway between the character's front and
// the arm's side, in the frame of the upper arm's parent (so it turns with the torso). A
// direction outside the cone (e.g. behind the character when the body does not turn) is moved
// onto the cone's boundary along the great circle toward the cone's axis: clamped, not flipped.
//
//   ArmChain arm = MakeArmChain(character.skeleton, {}, ArmSide::kRight, {}, forward, up);
//   Clip key = GenerateGestureClip(skeleton, base_clip, &lookat_chain, arm, Gesture::kPoint, v);
//   Eigen::Vector3d d = GestureDirection(arm, Gesture::kPoint, model_pose);   // for checks

#include "anim/character.h"
#include "anim/chains.h"
#include "anim/pose.h"
#include "anim_authoring/lookat.h"
#include "base/enum_table.h"

#include <span>
#include <string>
#include <vector>

namespace arview::authoring {

enum class Gesture { kNone, kPoint, kReach };
constexpr auto EnumNames(Gesture) {
  return EnumTable<Gesture, 3>{{{Gesture::kNone, "none"}, {Gesture::kPoint, "point"}, {Gesture::kReach, "reach"}}};
}

enum class ArmSide { kRight, kLeft };
constexpr auto EnumNames(ArmSide) { return EnumTable<ArmSide, 2>{{{ArmSide::kRight, "right"}, {ArmSide::kLeft, "left"}}}; }

// Upper arm, forearm and hand of one side found by name in common rigs: the wrist (CMU's
// "rwrist") or else hand joint ("RightHand", "mixamorig:RightHand", "B_Hand_Right", "hand_r")
// with its parent and grandparent; without either (CesiumMan's "Skeleton_arm_joint_R",
// "..._R__2_", "..._R__3_"), the side's first joint named like an (upper) arm and the next two
// joints below it. Empty when no such chain exists.
std::vector<std::string> DefaultArmChain(const anim::Skeleton& skeleton, ArmSide side);

// Builds the chain: `names` (upper arm, forearm, hand; empty: DefaultArmChain) must form one
// parent chain. Throws Error naming what is missing ("no right arm chain found by name ...").
anim::ArmChain MakeArmChain(const anim::Skeleton& skeleton, const std::vector<std::string>& names, ArmSide side,
                      const anim::ArmLimits& limits, const Eigen::Vector3d& forward,
                      const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

// Turns the arm of `pose` (model transforms in `model`, kept up to date) toward `target` (unit,
// model space) within the limits.
void ApplyGesture(const anim::Skeleton& skeleton, const anim::ArmChain& arm, Gesture gesture, const Eigen::Vector3d& target,
                  anim::LocalPose& pose, std::vector<Eigen::Matrix4d>& model);

// The base clip (nullptr: the rest pose) turned toward `viewpoint` by the look-at chain
// (nullptr: not turned), then the arm on top, at every sample (`sample_rate` Hz over the base
// clip). The result animates the look-at and arm joints; the others keep the base clip.
anim::Clip GenerateGestureClip(const anim::Skeleton& skeleton, const anim::Clip* base, const anim::LookAtChain* lookat, const anim::ArmChain& arm,
                         Gesture gesture, const Eigen::Vector3d& viewpoint, double sample_rate = 30.0);

// Checks on a pose given as model-space joint matrices:
// the gesture's direction (point: elbow → hand; reach: shoulder → hand), unit;
Eigen::Vector3d GestureDirection(const anim::ArmChain& arm, Gesture gesture, std::span<const Eigen::Matrix4d> model);
// the elbow's bend in degrees (0 = straight);
double ElbowBendDeg(const anim::ArmChain& arm, std::span<const Eigen::Matrix4d> model);
// the upper arm's angle from the shoulder cone's axis, in degrees.
double ShoulderConeAngleDeg(const anim::Skeleton& skeleton, const anim::ArmChain& arm, std::span<const Eigen::Matrix4d> model);

}  // namespace arview::authoring
