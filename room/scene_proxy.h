#pragma once
// A proxy of the real scene from a sparse map's points: planar patches. Sequential RANSAC finds
// the planes that hold most points; on each plane the inliers are binned in a grid of cells a
// few point spacings wide, the occupied cells are grouped into 8-connected components, and
// each component becomes the convex hull of its points (a triangle fan). The proxy is where
// light-estimation rays meet the scene, and the depth-only occluder drawn before the character.
//
// Limits: only what the map has points on exists. Textureless surfaces (bare walls, doors),
// thin things (chair legs, cables) and anything curved get no or partial patches; a concave
// patch (an L-shaped table top) is filled to its convex hull.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace arview::room {

struct PlaneProxyOptions {
  int max_planes = 16;
  int min_plane_points = 40;        // a plane with fewer inliers ends the search
  double inlier_fraction = 0.006;   // inlier distance, share of the points' robust extent
  double cell_spacings = 3.0;       // cell size, in median nearest-neighbour spacings of the plane's points
  int min_component_points = 12;    // smaller connected groups of cells are dropped as clutter
  int iterations = 400;
  std::uint64_t seed = 1;
};

struct ProxyPatch {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double offset = 0;                                   // normal·x + offset = 0
  int points = 0;
  std::vector<Eigen::Vector3f> triangles;              // 3 corners each
};

struct SceneProxy {
  std::vector<ProxyPatch> patches;
  // Every patch's triangles in one list (3 corners each).
  std::vector<Eigen::Vector3f> Triangles() const;
  // Drops the patches lying on a given plane (normal within `max_angle_deg`, offset within
  // `max_distance`): a character's own floor cannot hide it from a camera above that floor,
  // and leaving it in would fight with the character's feet and shadows in the depth buffer.
  void RemovePlane(const Eigen::Vector3d& normal, double offset, double max_angle_deg, double max_distance);
};

// Throws std::invalid_argument when there are fewer than 3 points.
SceneProxy BuildPlaneProxy(const std::vector<Eigen::Vector3d>& points, const PlaneProxyOptions& options = {});

}  // namespace arview::room
