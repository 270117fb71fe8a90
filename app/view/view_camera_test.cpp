// The orbit camera and the scripted orbit of `arview view`.

#include <gtest/gtest.h>

#include <cmath>

#include "anim/view_sphere.h"
#include "app/view/view_camera.h"
#include "app/view/view_orbit.h"

namespace arview::app {
namespace {

Eigen::Vector2d Pixel(const calib::Camera& k, const calib::Pose& pose, const Eigen::Vector3d& world) {
  const Eigen::Vector3d c = pose.ToCamera(world);
  return {k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy};
}

TEST(OrbitCamera, LooksAtTheTargetWithUpUpInTheImage) {
  const Eigen::Vector3d up(0, 0, 1), forward(1, 0, 0);  // a z-up map, character facing +x
  const OrbitCamera orbit(forward, up, {{1, 2, 0.5}, 30, 20, 3});
  const calib::Camera k = ViewCamera(1280, 720);
  const calib::Pose pose = orbit.Pose();
  EXPECT_NEAR((pose.Center() - orbit.Center()).norm(), 0, 1e-12);
  EXPECT_NEAR((orbit.Center() - Eigen::Vector3d(1, 2, 0.5)).norm(), 3, 1e-12);
  const Eigen::Vector2d target = Pixel(k, pose, {1, 2, 0.5});
  EXPECT_NEAR(target.x(), k.cx, 1e-9);
  EXPECT_NEAR(target.y(), k.cy, 1e-9);
  // A point above the target is higher in the image (smaller row), at the same column.
  const Eigen::Vector2d above = Pixel(k, pose, {1, 2, 1.0});
  EXPECT_LT(above.y(), target.y() - 10);
  EXPECT_NEAR(above.x(), target.x(), 1e-6);
}

TEST(OrbitCamera, AzimuthAndElevationAreTheKeyViewpointConvention) {
  const Eigen::Vector3d up(0, 1, 0), forward(0, 0, 1);
  for (double az : {-135.0, 0.0, 45.0, 90.0, 170.0}) {
    for (double el : {-30.0, 0.0, 60.0}) {
      const OrbitCamera orbit(forward, up, {Eigen::Vector3d::Zero(), az, el, 2});
      const Eigen::Vector3d expected = anim::DirectionFromAzimuthElevation(az, el, forward, up);
      EXPECT_NEAR((orbit.Center().normalized() - expected).norm(), 0, 1e-12) << az << " " << el;
    }
  }
}

TEST(OrbitCamera, DragOrbitsZoomScalesPanFollowsTheCursor) {
  OrbitCamera orbit({0, 0, 1}, {0, 1, 0}, {Eigen::Vector3d::Zero(), 10, 5, 2});
  orbit.Orbit(100, -50);
  EXPECT_NEAR(orbit.state().azimuth_deg, 10 - 100 * OrbitCamera::kDegPerPixel, 1e-12);
  EXPECT_NEAR(orbit.state().elevation_deg, 5 - 50 * OrbitCamera::kDegPerPixel, 1e-12);
  orbit.Orbit(0, 1000);  // clamped short of the pole
  EXPECT_DOUBLE_EQ(orbit.state().elevation_deg, OrbitCamera::kMaxElevationDeg);
  orbit.Zoom(2);
  EXPECT_NEAR(orbit.state().distance, 2 / (1.1 * 1.1), 1e-12);

  const calib::Camera k = ViewCamera(800, 600);
  OrbitCamera pan({0, 0, 1}, {0, 1, 0}, {Eigen::Vector3d::Zero(), 0, 0, 2});
  const calib::Pose before = pan.Pose();
  const Eigen::Vector2d p0 = Pixel(k, before, Eigen::Vector3d::Zero());
  pan.Pan(40, -25, k);
  // The world point that was at the centre moved with the cursor.
  const Eigen::Vector2d p1 = Pixel(k, pan.Pose(), Eigen::Vector3d::Zero());
  EXPECT_NEAR(p1.x() - p0.x(), 40, 1e-6);
  EXPECT_NEAR(p1.y() - p0.y(), -25, 1e-6);
  pan.Reset();
  EXPECT_NEAR(pan.state().target.norm(), 0, 1e-15);
}

TEST(OrbitSpec, ParsesRangesAndDefaults) {
  const OrbitSpec s = ParseOrbitSpec("azimuth=-90..270,elevation=10..30,distance=2.5,seconds=4");
  EXPECT_DOUBLE_EQ(s.azimuth_deg.from, -90);
  EXPECT_DOUBLE_EQ(s.azimuth_deg.to, 270);
  EXPECT_DOUBLE_EQ(s.elevation_deg->At(0.5), 20);
  EXPECT_DOUBLE_EQ(s.distance->At(0.7), 2.5);
  EXPECT_DOUBLE_EQ(s.seconds, 4);
  const OrbitState home{{0, 1, 0}, 30, 15, 3};
  const OrbitSpec d = ParseOrbitSpec("seconds=2");
  const OrbitState mid = OrbitAt(d, home, 0.25);
  EXPECT_DOUBLE_EQ(mid.azimuth_deg, 90);
  EXPECT_DOUBLE_EQ(mid.elevation_deg, 15);
  EXPECT_DOUBLE_EQ(mid.distance, 3);
}

TEST(OrbitSpec, BadSpecsNameTheField) {
  const std::pair<const char*, const char*> cases[] = {
      {"", "empty"},
      {"azimuth=a..b", "azimuth=a..b is not a number"},
      {"speed=3", "unknown field 'speed'"},
      {"elevation=95", "within"},
      {"distance=0", "distance must be > 0"},
      {"seconds=-1", "seconds must be"},
      {"azimuth=0..90,", "is not field=value"},
  };
  for (const auto& [spec, message] : cases) {
    try {
      ParseOrbitSpec(spec);
      ADD_FAILURE() << spec;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("--orbit: ", 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace arview::app
