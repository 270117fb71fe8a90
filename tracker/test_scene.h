#pragma once
// Synthetic 2D-3D scenes for the tracker's unit tests and benchmarks: a distorted 640x480
// camera, a random pose, points in front of it, Gaussian pixel noise and gross outliers.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <random>
#include <vector>

#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::tracker::testing {

inline calib::Camera TestCamera() {
  calib::Camera camera = calib::Camera::Pinhole(640, 480, 520.0, 518.0, 322.5, 241.0);
  camera.dist = {-0.21, 0.06, 0.0008, -0.0005, -0.004};
  return camera;
}

struct SyntheticScene {
  calib::Pose pose;  // ground truth, world → camera
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> is_outlier;
};

// Points are uniform over the image at depths 2..6 from a random camera pose; `outlier_ratio`
// of them get their pixel replaced by a uniform random one.
inline SyntheticScene MakeScene(const calib::Camera& camera, int count, double noise_px,
                                double outlier_ratio, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  SyntheticScene scene;
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  scene.pose.q_cw = Eigen::Quaterniond(Eigen::AngleAxisd(u(rng) * 3.0, axis));
  scene.pose.t_cw = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2.0;
  std::uniform_real_distribution<double> ux(0, camera.width - 1), uy(0, camera.height - 1),
      depth(2, 6);
  std::normal_distribution<double> noise(0, noise_px);
  std::bernoulli_distribution outlier(outlier_ratio);
  const Eigen::Matrix3d R_wc = scene.pose.q_cw.conjugate().toRotationMatrix();
  const Eigen::Vector3d C = scene.pose.Center();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d pixel(ux(rng), uy(rng));
    const Eigen::Vector3d bearing = camera.Unproject(pixel);
    const Eigen::Vector3d p_cam = bearing / bearing.z() * depth(rng);
    scene.points.push_back(R_wc * p_cam + C);
    const bool bad = outlier(rng);
    scene.is_outlier.push_back(bad);
    scene.pixels.push_back(bad ? Eigen::Vector2d(ux(rng), uy(rng))
                               : Eigen::Vector2d(pixel + Eigen::Vector2d(noise(rng), noise(rng))));
  }
  return scene;
}

inline double RotationErrorDeg(const calib::Pose& a, const calib::Pose& b) {
  return a.q_cw.angularDistance(b.q_cw) * 180.0 / M_PI;
}

}  // namespace arview::tracker::testing
