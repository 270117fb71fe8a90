#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "synth/orbit_walk.h"
#include "synth/synth_room.h"

namespace arview::synth {
namespace {

constexpr double kFps = 30;
constexpr int kFrames = 1340;  // the demo's walk: two laps of 22.3 s

// Distance from p to the rectangle with corners c[0..3].
double DistanceToPanel(const Eigen::Vector3d& p, const Eigen::Vector3d c[4]) {
  const Eigen::Vector3d u = c[1] - c[0], v = c[3] - c[0];
  const double s = std::clamp((p - c[0]).dot(u) / u.squaredNorm(), 0.0, 1.0);
  const double t = std::clamp((p - c[0]).dot(v) / v.squaredNorm(), 0.0, 1.0);
  return (p - (c[0] + s * u + t * v)).norm();
}

TEST(OrbitWalk, KeepsClearOfTheRoomsWallsAndBoxes) {
  const RoomScene scene = MakeRoomScene();
  const OrbitWalk walk(kFrames / kFps, 1);
  double nearest_wall = 1e9, nearest_box = 1e9;
  for (int i = 0; i < kFrames; i += 3) {
    const Eigen::Vector3d c = walk.At(i / kFps).Center();
    nearest_wall = std::min({nearest_wall, 3.5 - std::abs(c.x()), 2.5 - std::abs(c.y())});
    for (const RoomPanel& panel : scene.panels) {
      const bool on_a_box = panel.corners[0].z() < 1.25 && std::abs(panel.corners[0].x()) < 3.4 &&
                            std::abs(panel.corners[0].y()) < 2.4 && panel.corners[0].z() > 0.01;
      if (on_a_box) nearest_box = std::min(nearest_box, DistanceToPanel(c, panel.corners));
    }
    EXPECT_GT(c.z(), 1.4);
    EXPECT_LT(c.z(), 1.7);
  }
  EXPECT_GT(nearest_wall, 0.4);
  EXPECT_GT(nearest_box, 0.3);
}

TEST(OrbitWalk, SecondLapCirclesTheSubjectAndComesCloseOnce) {
  const OrbitWalk walk(kFrames / kFps, 1);
  const calib::Camera camera = RoomCamera();
  const Eigen::Vector3d chest = walk.Subject() + Eigen::Vector3d(0, 0, 1.1);
  int in_view = 0, close_frames = 0, close_runs = 0;
  bool was_close = false;
  double turned = 0, previous = 0, nearest = 1e9, farthest = 0;
  for (int i = kFrames / 2; i < kFrames; ++i) {
    const calib::Pose pose = walk.At(i / kFps);
    const Eigen::Vector3d offset = pose.Center() - walk.Subject();
    const double distance = offset.head<2>().norm();
    nearest = std::min(nearest, distance);
    farthest = std::max(farthest, distance);
    const bool close = distance < 1.5;
    close_frames += close;
    close_runs += close && !was_close;
    was_close = close;
    const Eigen::Vector3d c = pose.ToCamera(chest);
    in_view += c.z() > 0 && camera.InImage(camera.Project(c));
    const double azimuth = std::atan2(offset.y(), offset.x());
    if (i > kFrames / 2) turned += std::remainder(azimuth - previous, 2 * M_PI);
    previous = azimuth;
  }
  const int frames = kFrames - kFrames / 2;
  EXPECT_GT(in_view, 0.9 * frames);                // only the glance away leaves the character
  EXPECT_LT(in_view, frames);                      // ... which it does
  EXPECT_GT(std::abs(turned), 1.9 * M_PI);         // all the way round: behind it too
  EXPECT_EQ(close_runs, 1);
  EXPECT_GT(close_frames, 20);                     // lingers near it
  EXPECT_LT(close_frames, 0.25 * frames);
  EXPECT_NEAR(nearest, walk.options().close_distance, 0.05);
  EXPECT_LT(farthest, 4.0);
  // The close approach happens where the walk says it does (the demo turns the character there).
  const double close_azimuth = walk.CloseApproachAzimuth();
  const calib::Pose at_close = walk.At((kFrames / 2 + walk.options().close_fraction * frames) / kFps);
  const Eigen::Vector3d d = at_close.Center() - walk.Subject();
  EXPECT_LT(std::abs(std::remainder(std::atan2(d.y(), d.x()) - close_azimuth, 2 * M_PI)), 0.05);
}

TEST(OrbitWalk, IsSmoothAndRepeatable) {
  const OrbitWalk walk(kFrames / kFps, 1), again(kFrames / kFps, 1), other(kFrames / kFps, 2);
  double largest_step = 0, largest_turn = 0;
  for (int i = 1; i < kFrames; ++i) {
    const calib::Pose a = walk.At((i - 1) / kFps), b = walk.At(i / kFps);
    largest_step = std::max(largest_step, (a.Center() - b.Center()).norm());
    largest_turn = std::max(largest_turn, a.q_cw.angularDistance(b.q_cw));
  }
  EXPECT_LT(largest_step, 0.05);                 // < 1.5 m/s
  EXPECT_LT(largest_turn * 180 / M_PI, 10.0);    // the glance: ~270°/s at its peak
  EXPECT_GT(largest_turn * 180 / M_PI, 5.0);     // ... which is a fast turn
  EXPECT_EQ(walk.At(7.0).Center(), again.At(7.0).Center());
  EXPECT_GT((walk.At(7.0).Center() - other.At(7.0).Center()).norm() + walk.At(7.0).q_cw.angularDistance(other.At(7.0).q_cw), 1e-4);
}

TEST(OrbitWalk, FirstLapLooksAtEveryWall) {
  const OrbitWalk walk(kFrames / kFps, 1);
  int walls[4] = {0, 0, 0, 0};  // +x, -x, +y, -y: which wall the optical axis meets
  for (int i = 0; i < kFrames / 2; ++i) {
    const calib::Pose pose = walk.At(i / kFps);
    const Eigen::Vector3d c = pose.Center(), f = pose.CameraToWorldRotation() * Eigen::Vector3d::UnitZ();
    const double tx = f.x() > 0 ? (3.5 - c.x()) / f.x() : (-3.5 - c.x()) / f.x();
    const double ty = f.y() > 0 ? (2.5 - c.y()) / f.y() : (-2.5 - c.y()) / f.y();
    ++walls[tx < ty ? (f.x() > 0 ? 0 : 1) : (f.y() > 0 ? 2 : 3)];
  }
  for (int w = 0; w < 4; ++w) EXPECT_GT(walls[w], kFrames / 2 / 20) << "wall " << w;
}

}  // namespace
}  // namespace arview::synth
