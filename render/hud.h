#pragma once
// The overlay that shows what drives the view-adaptive blend (the self-adaptive paper's
// Figs. 2–3): the view sphere around the character, drawn in the scene as a wire globe through
// the camera that renders the frame; every key viewpoint on it as a dot coloured by its weight
// (dark blue at 0 through green to yellow at 1) and labelled with its index, what it plays and
// its weight; the current viewpoint in red; a panel with the weights as bars; and free text
// (status, help). Drawn on the CPU over the finished BGR frame, so it works the same over the
// window's floor and over an AR video frame.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <span>
#include <string>
#include <vector>

#include "anim/gaze.h"
#include "anim/placement.h"
#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::render {

struct HudKey {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit, character frame
  double weight = 0;
  std::string label;         // what the key plays: "Survey", "lookat", "rest", "Walk@0.25"
  bool highlighted = false;  // e.g. the key a "remove nearest" would take
};

struct HudSphere {
  std::string name;                                       // the character's
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();       // map coordinates (the anchor)
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // character frame → map
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();     // character frame axes
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  double radius = 1;                                      // map units
  std::vector<HudKey> keys;
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();   // current, character frame
};

struct HudText {
  std::vector<std::string> status;  // top left
  std::vector<std::string> help;    // bottom left (empty: none)
};

// What the overlay shows for a character: its view sphere centred on its anchor and sized 1.1x
// `height` (its rest height in map units), its keys (directions in the character's frame, with
// what each plays) with their weights this frame, and the viewpoint the animation used. Shared
// by the AR pipeline's `--hud` and `arview view`.
HudSphere HudSphereFor(const anim::Placement& placement, const std::string& name,
                       std::span<const Eigen::Vector3d> key_directions, std::span<const std::string> key_labels,
                       std::span<const double> weights, const Eigen::Vector3d& viewpoint, double height,
                       int highlighted_key = -1);

// The status line of a character's eyes (anim/gaze.h): "eye contact" while they are on the
// viewer, "eyes away" otherwise, with "  (blink)" during a blink; empty for a character without
// gaze.
std::string EyeContactLine(const anim::GazeFrame& eyes);

// BGR colour for a weight in [0, 1].
cv::Scalar WeightColour(double weight);

// Where a direction of the sphere lands in the image (false when behind the camera).
bool ProjectOnSphere(const HudSphere& sphere, const Eigen::Vector3d& direction, const calib::Camera& camera,
                     const calib::Pose& pose, cv::Point2d* pixel);

// Draws the spheres (through `camera`, a pinhole camera of the frame's size, at `pose`), the
// weight panel of the first sphere, and the text, over `frame` (8-bit BGR).
void DrawHud(cv::Mat& frame, const calib::Camera& camera, const calib::Pose& pose,
             const std::vector<HudSphere>& spheres, const HudText& text);

}  // namespace arview::render
