#pragma once
// Rays against a triangle soup, on the CPU: a bounding-volume hierarchy (median split on the
// longest centroid axis, up to 4 triangles a leaf) and Möller–Trumbore intersection. Used for
// the character's precomputed visibility (PRT), for where a keyframe pixel's ray meets the
// scene proxy (light estimation), and by tests that render exact synthetic keyframes.
// (The seed paper uses a uniform grid with Amanatides–Woo traversal; a BVH answers the same
// queries and copes better with a character's uneven triangle sizes.)

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace arview::room {

struct RayHit {
  float distance = 0;  // along the (unit) direction
  int triangle = -1;
};

class TriangleBvh {
 public:
  // `vertices[3 i .. 3 i + 2]` are triangle i's corners.
  explicit TriangleBvh(std::vector<Eigen::Vector3f> vertices);
  int triangle_count() const { return static_cast<int>(vertices_.size() / 3); }
  const std::vector<Eigen::Vector3f>& vertices() const { return vertices_; }

  // The nearest hit with distance in (t_min, t_max), skipping the triangles listed in `skip`
  // (sorted ascending); distance < 0 when nothing is hit. `direction` must be unit length.
  RayHit Nearest(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min, float t_max,
                 std::span<const int> skip = {}) const;
  // Whether anything is hit in (t_min, t_max) (stops at the first hit).
  bool Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min, float t_max,
                std::span<const int> skip = {}) const;

 private:
  struct Node {
    Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
    int first = 0, count = 0;  // leaf: triangles order_[first, first + count); inner: count = 0
    int right = 0;             // inner: right child (left child is the next node)
  };
  template <bool kAny>
  RayHit Trace(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min, float t_max,
               std::span<const int> skip) const;
  int Build(int first, int count, std::vector<Eigen::Vector3f>& centroids);

  std::vector<Eigen::Vector3f> vertices_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace arview::room
