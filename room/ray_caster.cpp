#include "room/ray_caster.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>

namespace arview::room {
namespace {

constexpr int kLeafSize = 4;

// Slab test; returns whether the box is entered within (t_min, t_max).
bool HitsBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Eigen::Vector3f& origin,
             const Eigen::Vector3f& inverse, float t_min, float t_max) {
  for (int a = 0; a < 3; ++a) {
    float t0 = (lo[a] - origin[a]) * inverse[a];
    float t1 = (hi[a] - origin[a]) * inverse[a];
    if (t0 > t1) std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
    if (t_max < t_min) return false;
  }
  return true;
}

// Möller–Trumbore; the distance or +inf.
float IntersectTriangle(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, const Eigen::Vector3f& a,
                        const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  const Eigen::Vector3f e1 = b - a, e2 = c - a;
  const Eigen::Vector3f p = direction.cross(e2);
  const float det = e1.dot(p);
  if (std::abs(det) < 1e-12f) return std::numeric_limits<float>::infinity();
  const float inv = 1.f / det;
  const Eigen::Vector3f s = origin - a;
  const float u = s.dot(p) * inv;
  if (u < 0.f || u > 1.f) return std::numeric_limits<float>::infinity();
  const Eigen::Vector3f q = s.cross(e1);
  const float v = direction.dot(q) * inv;
  if (v < 0.f || u + v > 1.f) return std::numeric_limits<float>::infinity();
  return e2.dot(q) * inv;
}

}  // namespace

TriangleBvh::TriangleBvh(std::vector<Eigen::Vector3f> vertices) : vertices_(std::move(vertices)) {
  vertices_.resize(vertices_.size() / 3 * 3);
  const int n = triangle_count();
  order_.resize(n);
  std::vector<Eigen::Vector3f> centroids(n);
  for (int i = 0; i < n; ++i) {
    order_[i] = i;
    centroids[i] = (vertices_[3 * i] + vertices_[3 * i + 1] + vertices_[3 * i + 2]) / 3.f;
  }
  nodes_.reserve(2 * n / kLeafSize + 2);
  if (n > 0) Build(0, n, centroids);
}

int TriangleBvh::Build(int first, int count, std::vector<Eigen::Vector3f>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  Eigen::Vector3f clo = lo, chi = hi;
  for (int i = first; i < first + count; ++i) {
    const int t = order_[i];
    for (int k = 0; k < 3; ++k) {
      lo = lo.cwiseMin(vertices_[3 * t + k]);
      hi = hi.cwiseMax(vertices_[3 * t + k]);
    }
    clo = clo.cwiseMin(centroids[t]);
    chi = chi.cwiseMax(centroids[t]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  if (count <= kLeafSize || chi[axis] - clo[axis] <= 0.f) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  const int half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  Build(first, half, centroids);
  const int right = Build(first + half, count - half, centroids);
  nodes_[index].right = right;
  return index;
}

template <bool kAny>
RayHit TriangleBvh::Trace(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min, float t_max,
                          std::span<const int> skip) const {
  RayHit best{-1.f, -1};
  if (nodes_.empty()) return best;
  const Eigen::Vector3f inverse = direction.cwiseInverse();
  float nearest = t_max;
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!HitsBox(node.lo, node.hi, origin, inverse, t_min, nearest)) continue;
    if (node.count == 0) {
      const int left = static_cast<int>(&node - nodes_.data()) + 1;
      // Nearer child last, so that it is popped first.
      const bool right_first = direction[0] < 0;  // a cheap ordering; correctness does not depend on it
      stack[top++] = right_first ? left : node.right;
      stack[top++] = right_first ? node.right : left;
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      const int t = order_[i];
      const float d = IntersectTriangle(origin, direction, vertices_[3 * t], vertices_[3 * t + 1], vertices_[3 * t + 2]);
      if (!(d > t_min && d < nearest)) continue;
      if (!skip.empty() && std::binary_search(skip.begin(), skip.end(), t)) continue;
      nearest = d;
      best = {d, t};
      if constexpr (kAny) return best;
    }
  }
  return best;
}

RayHit TriangleBvh::Nearest(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min, float t_max,
                            std::span<const int> skip) const {
  return Trace<false>(origin, direction, t_min, t_max, skip);
}

bool TriangleBvh::Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min, float t_max,
                           std::span<const int> skip) const {
  return Trace<true>(origin, direction, t_min, t_max, skip).triangle >= 0;
}

}  // namespace arview::room
