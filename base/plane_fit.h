#pragma once
// The dominant plane of a point cloud (a floor, a table): RANSAC over 3-point hypotheses near
// the middle of the cloud, then a least-squares refit on the winner's inliers. Options in, the
// plane with its inlier count out, as the other estimators (tracker/absolute_pose.h).

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace arview {

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double offset = 0;                                   // normal·x + offset = 0
  int inliers = 0;
  double Distance(const Eigen::Vector3d& x) const { return normal.dot(x) + offset; }
};

struct PlaneFitOptions {
  double inlier_distance = 0;    // 0: 1% of the cloud's robust extent (twice the median distance to the middle)
  double middle_fraction = 0.5;  // use the points within this fraction of the extent around the median
  int iterations = 500;
  std::uint64_t seed = 1;
  // When set, only planes whose normal lies within max_tilt_deg of this direction count.
  std::optional<Eigen::Vector3d> up_prior;
  double max_tilt_deg = 30;
};

// The component-wise median of the points, and the median distance from `from` (both with
// base/stats.h's one median definition). Empty input: zero.
Eigen::Vector3d ComponentMedian(const std::vector<Eigen::Vector3d>& points);
double MedianDistance(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& from);

// Throws arview::Error when there are fewer than 3 points or no plane holds 3 of them.
Plane FitDominantPlane(const std::vector<Eigen::Vector3d>& points, const PlaneFitOptions& options);

// Which way is up, from the cameras: people film a scene walking around it or along it at about
// the same height, so the normal of the plane the camera centres lie in is up; when the centres
// do not span a plane (a straight walk), the mean of the cameras' own up axes (−y of the image)
// is. Signed towards the cameras' side. Throws arview::Error when neither gives a direction.
Eigen::Vector3d UpFromCameras(const std::vector<Eigen::Vector3d>& camera_centres,
                              const std::vector<Eigen::Vector3d>& camera_up_axes);

// The floor under the cameras: the dominant plane of `points` among those within
// options.max_tilt_deg of the cameras' up (options.up_prior, else UpFromCameras), its normal
// turned towards the side the cameras are on. `up`, when given, receives the up used. Throws
// arview::Error (no up, no plane).
Plane FitFloorUnderCameras(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& camera_centres,
                           const std::vector<Eigen::Vector3d>& camera_up_axes, PlaneFitOptions options,
                           Eigen::Vector3d* up = nullptr);

}  // namespace arview
