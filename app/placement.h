#pragma once
// Where a character stands in a map: the dominant plane of the map's points near the middle of
// the scene (RANSAC), the character's up along the plane normal towards the cameras, facing the
// first keyframe, scaled to the scene.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

namespace arview::app {

struct PlacementError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double offset = 0;                                   // normal·x + offset = 0
  int inliers = 0;
  double Distance(const Eigen::Vector3d& x) const { return normal.dot(x) + offset; }
};

struct PlaneFitOptions {
  double inlier_distance = 0;   // 0: 1% of the scene's robust extent
  double middle_fraction = 0.5; // use the points within this fraction of the extent around the median
  int iterations = 500;
  std::uint64_t seed = 1;
  // When set, only planes whose normal lies within max_tilt_deg of this direction are floors.
  std::optional<Eigen::Vector3d> up_prior;
  double max_tilt_deg = 30;
};

// Throws PlacementError when there are fewer than 3 points or no plane holds enough of them.
Plane FitDominantPlane(const std::vector<Eigen::Vector3d>& points, const PlaneFitOptions& options);

struct Anchor {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // character frame → map frame
  double scale = 1;
};

struct PlacementOptions {
  PlaneFitOptions plane;
  // The character's height as a fraction of the median distance from the cameras to the anchor.
  double height_fraction = 0.3;
};

// Which way is up, from the cameras: people film a scene walking around it or along it at about
// the same height, so the normal of the plane the camera centres lie in is up; when the centres
// do not span a plane (a straight walk), the mean of the cameras' own up axes (−y of the image)
// is. Signed towards the cameras' side.
Eigen::Vector3d UpFromCameras(const std::vector<Eigen::Vector3d>& camera_centres,
                              const std::vector<Eigen::Vector3d>& camera_up_axes);

// Character frame convention (glTF): +Y up, +Z forward (the direction the character faces).
// `character_height` is the height of the character's bind pose in its own units. The floor is
// the dominant plane among those within options.plane.max_tilt_deg of UpFromCameras().
Anchor PlaceOnDominantPlane(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector3d>& camera_centres,
                            const std::vector<Eigen::Vector3d>& camera_up_axes, double character_height,
                            const PlacementOptions& options);

}  // namespace arview::app
