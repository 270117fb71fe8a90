#pragma once
// The joint chains a character's generated keys turn: the look-at chain (body, spine, neck,
// head) and the arm chain of a gesture. anim_authoring finds them by name and generates the key
// clips (lookat.h, gesture.h); the per-frame path reads them back, e.g. to measure where the head
// looks (the appliance's gaze figure).

#include <Eigen/Core>

#include <span>
#include <vector>

namespace arview::anim {

struct LookAtChain {
  std::vector<int> joints;              // root-most first; the last is the head
  std::vector<double> limits_rad;       // per joint, > 0
  Eigen::Vector3d head_forward_local = Eigen::Vector3d::UnitZ();  // in the head joint's frame
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();  // model space: turns are yaw about it first
};

struct ArmLimits {
  double elbow_min_deg = 0, elbow_max_deg = 150;  // bend: 0 = straight
  double shoulder_cone_deg = 100;                 // half-angle, (0, 180]
  double point_bend_deg = 10, reach_bend_deg = 40;
};

struct ArmChain {
  int upper = -1, fore = -1, hand = -1;  // joints: shoulder (upper arm), elbow (forearm), wrist (hand)
  ArmLimits limits;
  // In the frame of the upper arm's parent joint (the skeleton's root_parent if none), fixed at
  // the rest pose: the shoulder cone's axis and the direction the elbow drops toward.
  Eigen::Vector3d cone_axis_parent = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d pole_parent = -Eigen::Vector3d::UnitY();
};

// The head's forward axis in model space for a pose given as model-space joint matrices.
Eigen::Vector3d HeadForward(const LookAtChain& chain, std::span<const Eigen::Matrix4d> model);

}  // namespace arview::anim
