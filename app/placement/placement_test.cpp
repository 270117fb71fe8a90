#include "app/placement/placement.h"
#include "app/placement/place_character.h"
#include "figure/humanoid.h"
#include "tests/support/test_data.h"
#include "tests/support/textured_room.h"

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
    const Anchor a = PlaceOnFloor(s.points, s.cameras, {}, 1.8, {});
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
  const Anchor a = PlaceOnFloor(s.points, s.cameras, {}, 1.8, {});
  EXPECT_GT((a.rotation * Eigen::Vector3d::UnitY()).dot(s.normal), 0.99);
  EXPECT_GT(UpFromCameras(s.cameras, {}).cwiseAbs().dot(s.normal.cwiseAbs()), 0.99);
}

TEST(Placement, DegenerateInputsAreClearErrors) {
  EXPECT_THROW(FitDominantPlane({Eigen::Vector3d::Zero()}, {}), arview::Error);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(i, 0, 0);
  EXPECT_THROW(FitDominantPlane(line, {}), arview::Error);
  EXPECT_THROW(PlaceOnFloor(MakeScene(false).points, {}, {}, 1.0, {}), PlacementError);
}

}  // namespace
}  // namespace arview::app

namespace arview::app {
namespace {

// 300 points on the floor z = 0 (a fifth of them clutter above it), six cameras on a ring 1.5
// above it looking at the middle.
map::Map RingMap() {
  map::Map map;
  map.camera = calib::Camera::Pinhole(640, 480, 500, 500, 319.5, 239.5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int i = 0; i < 300; ++i) map.points.push_back({Eigen::Vector3d(u(rng), u(rng), i % 5 == 0 ? 1 + 0.3 * u(rng) : 0)});
  for (int k = 0; k < 6; ++k) {
    map::Keyframe kf;
    kf.frame_index = k;
    const double a = k * M_PI / 3;
    const Eigen::Vector3d centre(3 * std::cos(a), 3 * std::sin(a), 1.5);
    const Eigen::Vector3d forward = -centre.normalized(), right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    Eigen::Matrix3d r_wc;
    r_wc << right, forward.cross(right), forward;
    kf.pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r_wc), centre);
    map.keyframes.push_back(kf);
  }
  return map;
}

// On a metric map the character's height is metres: the user's, else the asset's own when it is
// a plausible height in metres (glTF's unit), else a person's.
TEST(PlaceCharacterHeight, MetresOnAMetricMap) {
  PlaceCharacterOptions o;
  EXPECT_DOUBLE_EQ(MetricHeight(o, 1.72), 1.72);           // the built-in figure, in metres
  EXPECT_DOUBLE_EQ(MetricHeight(o, 180.0), kDefaultHeightMetres);  // an asset in centimetres
  EXPECT_DOUBLE_EQ(MetricHeight(o, 0.01), kDefaultHeightMetres);
  o.height_m = 0.4;
  EXPECT_DOUBLE_EQ(MetricHeight(o, 180.0), 0.4);
}

// The same asset on the same map: a fraction of the viewing distance without scale, metres with.
TEST(PlaceCharacterHeight, AMetricMapSizesTheCharacterInMetres) {
  const std::filesystem::path asset = testing::SharedData("characters/CesiumMan.glb");
  ARVIEW_REQUIRE_DATA_PATH(asset, "../shared/data");
  map::Map map = RingMap();
  PlaceCharacterOptions o;
  o.key_elevation_deg = 0;
  const ScenePlacement unscaled = PlaceCharacter(map, asset, o);
  map.frame.scale_source = map::ScaleSource::kBoard;
  const ScenePlacement metric = PlaceCharacter(map, asset, o);
  EXPECT_NEAR(metric.anchor.scale * metric.rest_height, MetricHeight(o, metric.rest_height), 1e-9);
  EXPECT_NEAR(unscaled.anchor.scale * unscaled.rest_height, 0.3 * MedianDistance({map.keyframes[0].pose.Center()}, unscaled.anchor.position), 0.3);
  o.height_m = 0.5;
  EXPECT_NEAR(PlaceCharacter(map, asset, o).anchor.scale * metric.rest_height, 0.5, 1e-9);
}

// The first run without a scene: the figure stands where the first view's line of sight meets
// the floor, facing the camera, its scale kept.
TEST(StandInFrontOfView, StandsWhereTheLineOfSightMeetsTheFloorFacingTheCamera) {
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d up = tilt * Eigen::Vector3d::UnitY();
  Anchor on_floor;
  on_floor.position = Eigen::Vector3d(5, 0, 0);
  on_floor.rotation = Eigen::Quaterniond(tilt);
  on_floor.scale = 0.02;
  const Eigen::Vector3d along = tilt * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d camera = on_floor.position + 1.6 * up - 4 * tilt * Eigen::Vector3d::UnitX();
  // 30 degrees down: the floor is met 1.6 / tan(30) = 2.77 along it, within 1..3 heights of 1.7.
  const Eigen::Vector3d view = std::cos(M_PI / 6) * along - std::sin(M_PI / 6) * up;
  const Anchor a = StandInFrontOfView(on_floor, 1.7, camera, view);
  EXPECT_NEAR((a.position - on_floor.position).dot(up), 0, 1e-9);  // on the floor
  const Eigen::Vector3d under_camera = camera - 1.6 * up;
  EXPECT_NEAR((a.position - under_camera).norm(), 1.6 / std::tan(M_PI / 6), 1e-9);
  EXPECT_NEAR((a.position - under_camera).normalized().dot(along), 1, 1e-9);
  EXPECT_NEAR((a.rotation * Eigen::Vector3d::UnitY()).dot(up), 1, 1e-9);
  EXPECT_NEAR((a.rotation * Eigen::Vector3d::UnitZ()).dot(-along), 1, 1e-9);  // faces the camera
  EXPECT_EQ(a.scale, on_floor.scale);
}

TEST(StandInFrontOfView, ALevelOrSteepViewIsHeldWithinItsDistances) {
  Anchor on_floor;  // the floor y = 0, up +Y; its middle far away
  on_floor.position = Eigen::Vector3d(0, 0, 50);
  const Eigen::Vector3d camera(0, 1.6, 0);
  const double height = 1.7;
  const auto distance = [&](const Eigen::Vector3d& view) {
    const Anchor a = StandInFrontOfView(on_floor, height, camera, view);
    EXPECT_NEAR(a.position.y(), 0, 1e-9);
    return Eigen::Vector2d(a.position.x(), a.position.z()).norm();
  };
  EXPECT_NEAR(distance({0, 0, 1}), kFirstViewDistanceInHeights[1] * height, 1e-9);    // level: never meets it
  EXPECT_NEAR(distance({0, 0.5, 1}), kFirstViewDistanceInHeights[1] * height, 1e-9);  // looking up
  EXPECT_NEAR(distance({0, -1, 0.1}), kFirstViewDistanceInHeights[0] * height, 1e-9); // at its feet
  EXPECT_NEAR(distance({0, -1, 0}), kFirstViewDistanceInHeights[0] * height, 1e-9);   // straight down
  // The floor's middle 2.5 along the floor from the camera: no farther than it.
  on_floor.position = Eigen::Vector3d(1.5, 0, 2);
  EXPECT_NEAR(distance({0, 0, 1}), 2.5, 1e-9);
  on_floor.position = Eigen::Vector3d(0.3, 0, 0.4);  // nearer than one height: the near limit
  EXPECT_NEAR(distance({0, 0, 1}), kFirstViewDistanceInHeights[0] * height, 1e-9);
}

// `arview place --at --facing` writes the scene a first run stood: the floor's placement moved
// by StandAt, its scale and keys those of the placement without --at.
TEST(PlaceCharacterAt, IsTheFloorsPlacementMovedOnTheFloor) {
  figure::RegisterBuiltinCharacters();
  const map::Map map = RingMap();
  PlaceCharacterOptions o;
  const ScenePlacement middle = PlaceCharacter(map, "builtin:figure", o);
  o.stand_at = Eigen::Vector3d(0.5, -0.4, 0.3);  // above the floor: it stands below
  o.facing = Eigen::Vector3d(3, 0, 1.5);
  const ScenePlacement at = PlaceCharacter(map, "builtin:figure", o);
  const Anchor expected = StandAt(middle.anchor, *o.stand_at, *o.facing);
  EXPECT_TRUE(at.anchor.position.isApprox(expected.position, 1e-12));
  EXPECT_TRUE(at.anchor.rotation.isApprox(expected.rotation, 1e-12));
  EXPECT_NEAR(at.anchor.position.z(), 0, 0.02);  // the floor's RANSAC noise
  EXPECT_EQ(at.anchor.scale, middle.anchor.scale);
  EXPECT_EQ(at.key_elevation_deg, middle.key_elevation_deg);
  const Eigen::Vector3d up = at.anchor.rotation * Eigen::Vector3d::UnitY();
  Eigen::Vector3d to_facing = *o.facing - at.anchor.position;
  to_facing -= to_facing.dot(up) * up;
  EXPECT_NEAR((at.anchor.rotation * Eigen::Vector3d::UnitZ()).dot(to_facing.normalized()), 1, 1e-9);
}

}  // namespace
}  // namespace arview::app

namespace arview::app {
namespace {

// A room whose walls are textured densely and whose floor is plain (the rendered venue's): the
// character stands on the floor, not on the slice through the walls that is the dominant plane
// near-perpendicular to up (base/lowest_floor.h).
TEST(Placement, StandsOnThePlainFloorOfARoomWithDenselyTexturedWalls) {
  const testing::TexturedRoom room = testing::MakeTexturedRoom({1.5});
  const Anchor a = PlaceOnFloor(room.points, room.camera_centres, room.camera_up_axes, 1.8, {});
  EXPECT_NEAR(a.position.z(), 0, 0.02) << "stood at " << a.position.transpose();
  EXPECT_GT((a.rotation * Eigen::Vector3d::UnitY()).z(), 0.999);
  // Inside the room, on its floor.
  EXPECT_LT(std::abs(a.position.x()), 2.5);
  EXPECT_LT(std::abs(a.position.y()), 2.0);
}

}  // namespace
}  // namespace arview::app
