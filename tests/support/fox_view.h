#pragma once
// The Fox of ../shared/data standing in a z-up map, and a camera looking at it: the scene the
// renderer's and the compositor's tests draw (the fox fills part of a 640x480 view).

#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "calib/camera.h"
#include "tests/support/test_data.h"

namespace arview::testing {

// A scene file's text: the Fox at 1 %, anchored at (0.2, 0.1, 0), walking.
inline std::string FoxSceneYaml() {
  return "characters:\n  - name: fox\n    asset: " + SharedData("characters/Fox/glTF-Binary/Fox.glb").string() +
         "\n    scale: 0.01\n    anchor:\n      position: [0.2, 0.1, 0]\n"
         "      rotation_deg: [90, 0, 30]\n    keys:\n      - viewpoint: [0, 0, 1]\n"
         "        clip: Walk\n";
}

// A camera at `eye` looking at `target`, z up (image rows down the map's z).
inline calib::Pose LookingAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r_wc;
  r_wc << right, forward.cross(right), forward;
  return calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r_wc), eye);
}

// Looking at the anchor from 2 m, 0.8 m up, z up.
inline calib::Pose LookingAtFox() { return LookingAt({0.9, -1.8, 0.8}, {0.2, 0.1, 0.35}); }

}  // namespace arview::testing
