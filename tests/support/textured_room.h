#pragma once
// A room of 5 x 4 m as the rendered venue's (docs/mapping.md, "Metric scale and up"), in metres,
// z up: walls textured densely from 0.55 to 2.45 m (6,000 points), a plain floor at z = 0 with
// few points, and cameras turning round the room on a ring of 0.6 m at `heights` (one camera
// each, in turn), looking at the walls a little downwards. The dominant plane near-perpendicular
// to up of such a cloud is a horizontal slice through the walls, not the floor: the case the
// floor searches (base/lowest_floor.h) are tested on.

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arview::testing {

struct TexturedRoom {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> camera_centres;
  std::vector<Eigen::Vector3d> camera_targets;   // a point each camera looks at
  std::vector<Eigen::Vector3d> camera_up_axes;   // each camera's −y (up in its image)
};

inline constexpr int kTexturedRoomCameras = 24;
inline constexpr double kTexturedRoomWallBottom = 0.55;

inline TexturedRoom MakeTexturedRoom(const std::vector<double>& heights, int floor_points = 120) {
  TexturedRoom room;
  for (int k = 0; k < kTexturedRoomCameras; ++k) {
    const double a = 2 * M_PI * k / kTexturedRoomCameras;
    const Eigen::Vector3d centre(0.6 * std::cos(a), 0.6 * std::sin(a), heights[k % heights.size()]);
    const Eigen::Vector3d forward = Eigen::Vector3d(std::cos(a), std::sin(a), -0.1).normalized();
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    room.camera_centres.push_back(centre);
    room.camera_targets.push_back(centre + forward);
    room.camera_up_axes.push_back(-forward.cross(right));
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-2.5, 2.5), y(-2, 2), z(kTexturedRoomWallBottom, 2.45), side(0, 1);
  for (int i = 0; i < 6000; ++i) {
    const bool long_wall = side(rng) < 5.0 / 9;
    const double sign = side(rng) < 0.5 ? -1 : 1;
    room.points.push_back(long_wall ? Eigen::Vector3d(x(rng), 2 * sign, z(rng)) : Eigen::Vector3d(2.5 * sign, y(rng), z(rng)));
  }
  for (int i = 0; i < floor_points; ++i) room.points.emplace_back(x(rng), y(rng), 0);
  return room;
}

}  // namespace arview::testing
