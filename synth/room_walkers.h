#pragma once
// People walking through the synthetic room (`arview synth room --walkers N`): one to three of
// the built-in figure (figure/humanoid.h) playing its walk cycle while they pace circles round
// a spot on the floor (the demo's character spot on the orbit walk), so that they pass between
// the camera and the room's surfaces, and in front of the character's anchor, whichever side
// the camera looks from. They are drawn into the frames only: never in a map's keyframes unless
// the mapped frames show them (map the first lap, start them with --walkers-from).

#include <Eigen/Core>

#include <memory>
#include <vector>

#include "anim/character.h"
#include "anim/pose.h"
#include "render/character_renderer.h"

namespace arview::synth {

inline constexpr int kMaxWalkers = 3;

struct WalkersOptions {
  int count = 0;                          // 0..kMaxWalkers
  double from_s = 0;                      // recording time they appear at, walking
  Eigen::Vector2d spot{0, 0};             // the floor point their circles go round
};

// Where walker `i` is at recording time t: its feet's point on the floor, the way it faces
// (unit, horizontal) and its walk clip's time. Deterministic.
struct WalkerState {
  Eigen::Vector3d position;
  Eigen::Vector3d heading;
  double clip_time = 0;
};
// The circle walker i paces: radius (m), direction (+1 counter-clockwise seen from above),
// starting angle (radians, from +x). A walker makes way for the camera: its circle shrinks to
// keep kKeepAwayFromCamera between them when the camera comes closer to the spot, down to a
// radius of 0.2 m (0.95 m from the camera at the demo's close approach, 1.15 m from the spot),
// which keeps two walkers under about 40% of the frame on the demo's lap.
struct WalkerCircle {
  double radius;
  double direction;
  double start_angle;
};
WalkerCircle WalkerPath(int i);
inline constexpr double kKeepAwayFromCamera = 1.0;  // metres, on the floor
WalkerState WalkerAt(const WalkersOptions& options, int i, double t, const Eigen::Vector3d& camera_centre);
// The figure's model (metres, +Y up, facing +Z) to the room's world (z up) for a state.
Eigen::Matrix4d WalkerModelToWorld(const WalkerState& state);

// Draws the walkers into the bound framebuffer (depth tested against what is drawn there).
class WalkersRenderer {
 public:
  WalkersRenderer(const render::GlApi& gl, const WalkersOptions& options);
  void Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, double t);

 private:
  WalkersOptions options_;
  anim::Character figure_;
  anim::Clip walk_;
  render::CharacterRenderer renderer_;
  anim::LocalPose local_;
  std::vector<Eigen::Matrix4d> model_;
  std::vector<Eigen::Matrix4f> matrices_;
  std::vector<anim::DualQuatf> dual_quats_;
};

}  // namespace arview::synth
