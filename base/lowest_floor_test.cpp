#include "base/lowest_floor.h"

#include <gtest/gtest.h>

#include <random>

#include "base/error.h"
#include "tests/support/textured_room.h"

namespace arview {
namespace {

// Any point of the floor z = 0, against a plane found.
double HeightOfTheFloorOver(const Plane& plane) { return std::abs(plane.Distance(Eigen::Vector3d(0.3, -0.2, 0))); }

TEST(LowestFloor, IsTheFloorUnderDenselyTexturedWallsNotASliceThroughThem) {
  const testing::TexturedRoom room = testing::MakeTexturedRoom({1.5});
  // The reason for the search: the dominant plane near-perpendicular to up is a slice.
  const Plane dominant = FitFloorUnderCameras(room.points, room.camera_centres, room.camera_up_axes, {});
  ASSERT_GT(HeightOfTheFloorOver(dominant), 0.3) << "the scene no longer reproduces the walls' slice";

  const LowestFloor found = FindLowestFloor(room.points, room.camera_centres, room.camera_up_axes);
  EXPECT_LT(HeightOfTheFloorOver(found.floor), 0.02);
  EXPECT_GT(found.floor.normal.z(), std::cos(1.0 * M_PI / 180)) << "turned towards the cameras, upright";
  EXPECT_GT(found.up.z(), 0.99);
  EXPECT_LT(found.below_share, 0.01);
}

TEST(LowestFloor, AFloorThatIsAlsoTheDominantPlaneIsKeptAndNothingUnderItIsTaken) {
  // A dense floor, a table top above it, a few stray points below (wrong matches).
  std::vector<Eigen::Vector3d> points, centres, up_axes;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2, 2), stray(-2, -0.2);
  for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), 0);
  for (int i = 0; i < 800; ++i) points.emplace_back(0.2 * u(rng), 0.2 * u(rng), 0.75);
  for (int i = 0; i < 20; ++i) points.emplace_back(u(rng), u(rng), stray(rng));
  for (int k = 0; k < 12; ++k) {
    const double a = 2 * M_PI * k / 12;
    centres.emplace_back(2.5 * std::cos(a), 2.5 * std::sin(a), 1.6);
    up_axes.push_back(Eigen::Vector3d::UnitZ());
  }
  const LowestFloor found = FindLowestFloor(points, centres, up_axes);
  EXPECT_LT(HeightOfTheFloorOver(found.floor), 0.01);
  EXPECT_NEAR(found.below_share, 20.0 / points.size(), 1e-9);
}

TEST(LowestFloor, NoPlaneAcrossUpIsAnErrorSayingSo) {
  // Only walls: every plane the points hold stands along the cameras' up.
  testing::TexturedRoom room = testing::MakeTexturedRoom({1.5}, 0);
  std::vector<Eigen::Vector3d> one_wall;
  for (const Eigen::Vector3d& p : room.points)
    if (std::abs(p.y() - 2) < 1e-9) one_wall.push_back(p);
  ASSERT_GT(one_wall.size(), 1000u);
  try {
    FindLowestFloor(one_wall, room.camera_centres, room.camera_up_axes);
    FAIL() << "a wall was taken for the floor";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no floor-like plane"), std::string::npos) << e.what();
  }
  EXPECT_THROW(FindLowestFloor({Eigen::Vector3d::Zero()}, room.camera_centres, room.camera_up_axes), Error);
}

}  // namespace
}  // namespace arview
