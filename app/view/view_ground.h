#pragma once
// The floor of `arview view`: a grid on the character's ground plane (through the anchor,
// normal = the character's up), drawn on the CPU as the background the character is
// composited over — the place the video takes in AR. The character always stands on it, so
// drawing it behind the character is right for every view from above the floor.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::app {

struct GroundGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // map coordinates, on the floor
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ(); // in the floor plane
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  double cell = 0.25;  // map units
  int half_cells = 12; // the grid spans ±half_cells cells around the origin
};

// A round cell size (1, 2 or 5 × 10^n) near half the character's height.
double GridCellFor(double character_height);

// The background image: sky colour above, the floor quad, the grid lines; the line through
// the origin along the character's forward is drawn in a distinct colour. Lines are clipped
// at the camera's near plane.
cv::Mat RenderGround(const GroundGrid& grid, const calib::Camera& camera, const calib::Pose& pose);

}  // namespace arview::app
