#include "render/shadow_capsules.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace arview::render {
namespace {

// Measured against the skinned meshes' own outlines seen from a light (lighting_test.cpp,
// CastShadow.CapsulesCoverTheSkinnedMeshSeenFromTheLight; IoU for the Fox's Walk and Survey
// clips / CesiumMan's rest pose): with each vertex in its heaviest joint only and the radius
// that holds every vertex, 0.71–0.75 / 0.80 (the capsules ~25% too wide for bodies that are not
// round, and gaps at the bends); a vertex also in every joint that carries 35% of its weight
// (the capsules then overlap at the bends) and the radius holding 75% of the vertices,
// 0.82–0.83 / 0.86, covering 94–98% of the mesh's outline.
constexpr float kShareWeight = 0.35f;
constexpr double kRadiusQuantile = 0.75;

}  // namespace

std::vector<ShadowCapsule> FitShadowCapsules(const anim::Character& character) {
  const int joints = std::max(1, character.skeleton.size());
  // The vertices in the bind-pose frames of their heaviest joint and of every joint with a large share.
  std::vector<std::vector<Eigen::Vector3d>> local(joints);
  for (const anim::Mesh& mesh : character.meshes) {
    for (size_t i = 0; i < mesh.positions.size() && i < mesh.joints.size() && i < mesh.weights.size(); ++i) {
      int heaviest = 0;
      mesh.weights[i].maxCoeff(&heaviest);
      for (int k = 0; k < 4; ++k) {
        if (k != heaviest && !(mesh.weights[i][k] >= kShareWeight)) continue;
        const int j = mesh.joints[i][k];
        if (j >= joints) continue;
        const Eigen::Vector3d p = mesh.positions[i].cast<double>();
        const bool has_bind = j < static_cast<int>(character.skeleton.inverse_bind.size());
        local[j].push_back(has_bind ? (character.skeleton.inverse_bind[j] * p.homogeneous()).head<3>() : p);
      }
    }
  }
  std::vector<ShadowCapsule> capsules;
  for (int j = 0; j < joints; ++j) {
    const std::vector<Eigen::Vector3d>& points = local[j];
    if (points.empty()) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) mean += p;
    mean /= static_cast<double>(points.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& p : points) covariance += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
    const Eigen::Vector3d axis = eigen.eigenvectors().col(2);  // the largest eigenvalue's
    std::vector<double> along(points.size()), across(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d d = points[i] - mean;
      along[i] = d.dot(axis);
      across[i] = (d - along[i] * axis).norm();
    }
    std::vector<double> sorted = across;
    const auto rank = sorted.begin() + static_cast<std::ptrdiff_t>(kRadiusQuantile * static_cast<double>(sorted.size() - 1) + 0.5);
    std::nth_element(sorted.begin(), rank, sorted.end());
    const double radius = *rank;
    // The shortest segment [s0, s1] on the axis whose capsule holds every vertex within the
    // radius of the axis and spans the others along it: a vertex at `along` t and distance r
    // from the axis needs s0 <= t + sqrt(max(R² − r², 0)) and s1 >= t − sqrt(max(R² − r², 0)).
    double s0 = 1e300, s1 = -1e300;
    for (size_t i = 0; i < points.size(); ++i) {
      const double reach = std::sqrt(std::max(0.0, radius * radius - across[i] * across[i]));
      s0 = std::min(s0, along[i] + reach);
      s1 = std::max(s1, along[i] - reach);
    }
    if (s0 > s1) s0 = s1 = (s0 + s1) / 2;  // any point of [s1, s0] holds them all
    capsules.push_back({j, mean + s0 * axis, mean + s1 * axis, radius});
  }
  return capsules;
}

std::vector<ShadowCapsule> PoseShadowCapsules(std::span<const ShadowCapsule> capsules,
                                              std::span<const Eigen::Matrix4d> joint_to_map) {
  std::vector<ShadowCapsule> posed;
  posed.reserve(capsules.size());
  for (const ShadowCapsule& c : capsules) {
    if (c.joint < 0 || c.joint >= static_cast<int>(joint_to_map.size())) continue;
    const Eigen::Matrix4d& m = joint_to_map[c.joint];
    const double scale = m.topLeftCorner<3, 3>().colwise().norm().maxCoeff();
    posed.push_back({c.joint, (m * c.a.homogeneous()).head<3>(), (m * c.b.homogeneous()).head<3>(), c.radius * scale});
  }
  return posed;
}

void CapsuleBounds(std::span<const ShadowCapsule> posed, Eigen::Vector3d* centre, double* radius) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const ShadowCapsule& c : posed) {
    const Eigen::Vector3d r = Eigen::Vector3d::Constant(c.radius);
    lo = lo.cwiseMin(c.a - r).cwiseMin(c.b - r);
    hi = hi.cwiseMax(c.a + r).cwiseMax(c.b + r);
  }
  *centre = (lo + hi) / 2;
  *radius = 0;
  for (const ShadowCapsule& c : posed) {
    *radius = std::max(*radius, std::max((c.a - *centre).norm(), (c.b - *centre).norm()) + c.radius);
  }
}

void CapsuleCoverage(std::span<const ShadowCapsule> posed, const Eigen::Matrix4d& map_to_clip, double softness, int size,
                     cv::Mat* coverage, cv::Rect* support) {
  coverage->create(size, size, CV_8U);
  coverage->setTo(0);
  int x0 = size, y0 = size, x1 = -1, y1 = -1;  // the support's corners, inclusive
  const double texel = 2.0 / size;
  // The orthographic view scales every direction across the light by the same factor.
  const double to_clip = map_to_clip.block<1, 3>(0, 0).norm();
  const double s = std::max(softness, 1e-9);
  for (const ShadowCapsule& c : posed) {
    const Eigen::Vector2d a = (map_to_clip * c.a.homogeneous()).head<2>();
    const Eigen::Vector2d b = (map_to_clip * c.b.homogeneous()).head<2>();
    const double r = c.radius * to_clip;
    const double reach = r + s;
    // The texels the capsule can touch: its segment's box widened by its reach.
    auto first = [&](double lo) { return std::clamp(static_cast<int>(std::floor((lo + 1) / texel - 0.5)), 0, size); };
    auto last = [&](double hi) { return std::clamp(static_cast<int>(std::ceil((hi + 1) / texel - 0.5)) + 1, 0, size); };
    const int c0 = first(std::min(a.x(), b.x()) - reach), c1 = last(std::max(a.x(), b.x()) + reach);
    const int r0 = first(std::min(a.y(), b.y()) - reach), r1 = last(std::max(a.y(), b.y()) + reach);
    const Eigen::Vector2d ab = b - a;
    const double length2 = ab.squaredNorm();
    for (int row = r0; row < r1; ++row) {
      std::uint8_t* out = coverage->ptr<std::uint8_t>(row);
      const double y = -1 + (row + 0.5) * texel;
      for (int col = c0; col < c1; ++col) {
        const Eigen::Vector2d p(-1 + (col + 0.5) * texel, y);
        const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
        const double d = (p - a - t * ab).norm();
        if (d >= reach) continue;
        // smoothstep from r + s (nothing) to r − s (full).
        const double x = std::clamp((reach - d) / (2 * s), 0.0, 1.0);
        const auto value = static_cast<std::uint8_t>(std::lround(255 * x * x * (3 - 2 * x)));
        if (value == 0) continue;
        out[col] = std::max(out[col], value);
        x0 = std::min(x0, col), x1 = std::max(x1, col), y0 = std::min(y0, row), y1 = std::max(y1, row);
      }
    }
  }
  *support = x1 < 0 ? cv::Rect() : cv::Rect(cv::Point(x0, y0), cv::Point(x1 + 1, y1 + 1));
}

}  // namespace arview::render
