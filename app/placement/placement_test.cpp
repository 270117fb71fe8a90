#include "app/placement/placement.h"

#include <gtest/gtest.h>

#include <random>

namespace arview::app {
namespace {

// A tilted floor of 2000 points, 30% clutter above it, cameras on a ring above.
struct Scene {
  std::vector<Eigen::Vector3d> points, cameras;
  Eigen::Vector3d normal;
};

Scene MakeScene(bool cameras_below) {
  Scene s;
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  s.normal = tilt * Eigen::Vector3d::UnitZ();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, 0.002);
  for (int i = 0; i < 2000; ++i) s.points.push_back(tilt * Eigen::Vector3d(u(rng), u(rng), noise(rng)) + Eigen::Vector3d(5, 0, 0));
  for (int i = 0; i < 600; ++i) s.points.push_back(tilt * Eigen::Vector3d(u(rng), u(rng), 0.2 + std::abs(u(rng))) + Eigen::Vector3d(5, 0, 0));
  for (int i = 0; i < 12; ++i) {
    const double a = i * 2 * M_PI / 12;
    s.cameras.push_back(tilt * Eigen::Vector3d(2 * std::cos(a), 2 * std::sin(a), cameras_below ? -1.5 : 1.5) + Eigen::Vector3d(5, 0, 0));
  }
  return s;
}

TEST(Placement, FindsTheDominantPlaneDespiteClutter) {
  const Scene s = MakeScene(false);
  const Plane p = FitDominantPlane(s.points, {});
  EXPECT_GT(std::abs(p.normal.dot(s.normal)), 0.999);
  EXPECT_GT(p.inliers, 900);
}

TEST(Placement, UpPointsTowardsTheCamerasAndFacesTheFirstOne) {
  for (bool below : {false, true}) {
    const Scene s = MakeScene(below);
    const Anchor a = PlaceOnDominantPlane(s.points, s.cameras, {}, 1.8, {});
    const Eigen::Matrix3d r = a.rotation.toRotationMatrix();
    const Eigen::Vector3d up = r.col(1);
    EXPECT_GT(up.dot(below ? -s.normal : s.normal), 0.999);
    EXPECT_NEAR(a.rotation.norm(), 1, 1e-9);
    Eigen::Vector3d to_cam = s.cameras[0] - a.position;
    to_cam -= to_cam.dot(up) * up;
    EXPECT_GT(r.col(2).dot(to_cam.normalized()), 0.999);
    // Standing on the plane, about the scene's middle.
    EXPECT_LT(std::abs(s.normal.dot(a.position - Eigen::Vector3d(5, 0, 0))), 0.01);
    EXPECT_GT(a.scale, 0);
  }
}

// A wall as large as the floor: the cameras' ring says which one is the floor.
TEST(Placement, TheCamerasRingTellsTheFloorFromAWall) {
  Scene s = MakeScene(false);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int i = 0; i < 2500; ++i) s.points.push_back(tilt * Eigen::Vector3d(0.3, u(rng), 1 + u(rng)) + Eigen::Vector3d(5, 0, 0));
  const Anchor a = PlaceOnDominantPlane(s.points, s.cameras, {}, 1.8, {});
  EXPECT_GT((a.rotation * Eigen::Vector3d::UnitY()).dot(s.normal), 0.99);
  EXPECT_GT(UpFromCameras(s.cameras, {}).cwiseAbs().dot(s.normal.cwiseAbs()), 0.99);
}

TEST(Placement, DegenerateInputsAreClearErrors) {
  EXPECT_THROW(FitDominantPlane({Eigen::Vector3d::Zero()}, {}), arview::Error);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(i, 0, 0);
  EXPECT_THROW(FitDominantPlane(line, {}), arview::Error);
  EXPECT_THROW(PlaceOnDominantPlane(MakeScene(false).points, {}, {}, 1.0, {}), PlacementError);
}

}  // namespace
}  // namespace arview::app
