#include "synth/room_walkers.h"

#include <algorithm>
#include <cmath>

#include "figure/humanoid.h"
#include "render/render_error.h"

namespace arview::synth {

WalkerCircle WalkerPath(int i) {
  // Radii between the character's own reach and the camera's ring (1.15 m at its nearest): the
  // walkers pass close in front of the anchor without walking into the camera; alternate
  // directions, so two walkers cross each other as well as the camera's line of sight.
  static constexpr WalkerCircle kCircles[kMaxWalkers] = {{0.55, 1, 0.0}, {0.75, -1, 2.4}, {0.65, 1, 4.3}};
  return kCircles[i];
}

WalkerState WalkerAt(const WalkersOptions& options, int i, double t, const Eigen::Vector3d& camera_centre) {
  const WalkerCircle circle = WalkerPath(i);
  const double walked = std::max(0.0, t - options.from_s);
  const double angle = circle.start_angle + circle.direction * figure::kWalkSpeed * walked / circle.radius;
  const double camera_to_spot = (camera_centre.head<2>() - options.spot).norm();
  const double radius = std::clamp(camera_to_spot - kKeepAwayFromCamera, 0.2, circle.radius);
  WalkerState state;
  state.position = {options.spot.x() + radius * std::cos(angle), options.spot.y() + radius * std::sin(angle), 0};
  state.heading = Eigen::Vector3d(-std::sin(angle), std::cos(angle), 0) * circle.direction;
  state.clip_time = walked;
  return state;
}

Eigen::Matrix4d WalkerModelToWorld(const WalkerState& state) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 1>(0, 0) = up.cross(state.heading);  // model X = Y × Z
  m.block<3, 1>(0, 1) = up;
  m.block<3, 1>(0, 2) = state.heading;
  m.block<3, 1>(0, 3) = state.position;
  return m;
}

WalkersRenderer::WalkersRenderer(const render::GlApi& gl, const WalkersOptions& options)
    : options_(options),
      figure_(figure::MakeHumanoid()),
      walk_(figure::MakeHumanoidWalk()),
      renderer_(gl, figure_),
      local_(figure_.skeleton.size()),
      model_(figure_.skeleton.size()),
      matrices_(figure_.skeleton.size()),
      dual_quats_(figure_.skeleton.size()) {
  if (options.count < 0 || options.count > kMaxWalkers) {
    throw render::RenderError("synth room: --walkers must be in 0.." + std::to_string(kMaxWalkers) + ", got " +
                              std::to_string(options.count));
  }
}

void WalkersRenderer::Draw(const Eigen::Matrix4d& projection, const Eigen::Matrix4d& view, double t) {
  if (t < options_.from_s) return;
  const Eigen::Vector3d camera_centre = -view.block<3, 3>(0, 0).transpose() * view.block<3, 1>(0, 3);
  for (int i = 0; i < options_.count; ++i) {
    const WalkerState state = WalkerAt(options_, i, t, camera_centre);
    const bool posed = anim::SamplingJob{&figure_.skeleton, &walk_, state.clip_time, true, &local_}.Run() &&
                       anim::LocalToModelJob{&figure_.skeleton, &local_, model_}.Run() &&
                       anim::SkinningMatricesJob{&figure_.skeleton, model_, matrices_, dual_quats_}.Run();
    if (!posed) throw render::RenderError("synth room: internal error: the walk clip does not fit the figure");
    render::CharacterDraw draw;
    draw.model_to_map = WalkerModelToWorld(state);
    draw.skinning_matrices = matrices_;
    draw.skinning_dual_quats = dual_quats_;
    renderer_.Draw(projection, view, draw);
  }
}

}  // namespace arview::synth
