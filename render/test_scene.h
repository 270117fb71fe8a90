#pragma once
// Shared by render/'s tests (header-only so that it stays out of the library): an offscreen
// context for the whole test binary (llvmpipe's thread count is fixed per process) and
// flat-coloured geometry.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <cmath>
#include <memory>

#include "render/offscreen.h"
#include "render/textured_scene.h"

namespace arview::render::testing {

inline OffscreenOptions GlOptions(GlBackend backend, int threads) {
  OffscreenOptions options;
  options.backend = backend;
  options.threads = threads;
  return options;
}

inline OffscreenContext& SharedContext() {
  static std::unique_ptr<OffscreenContext> context = OffscreenContext::Create(GlOptions(GlBackend::kAuto, 2));
  context->MakeCurrent();
  return *context;
}

inline cv::Mat WhiteTexture() { return cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(255)); }

// A flat disc of `radius` centred at `center`, facing `eye`, as a triangle fan.
inline TriangleBatch Disc(const Eigen::Vector3d& center, double radius, const Eigen::Vector3d& eye,
                          const Eigen::Vector3f& color) {
  const Eigen::Vector3d normal = (eye - center).normalized();
  const Eigen::Vector3d a = normal.unitOrthogonal();
  const Eigen::Vector3d b = normal.cross(a);
  TriangleBatch batch;
  constexpr int kSegments = 48;
  auto vertex = [&](const Eigen::Vector3d& p) {
    return SceneVertex{{float(p.x()), float(p.y()), float(p.z())}, {0.5f, 0.5f}, {color.x(), color.y(), color.z()}};
  };
  for (int i = 0; i < kSegments; ++i) {
    const double a0 = 2 * M_PI * i / kSegments, a1 = 2 * M_PI * (i + 1) / kSegments;
    batch.vertices.push_back(vertex(center));
    batch.vertices.push_back(vertex(center + radius * (std::cos(a0) * a + std::sin(a0) * b)));
    batch.vertices.push_back(vertex(center + radius * (std::cos(a1) * a + std::sin(a1) * b)));
  }
  return batch;
}

// The 8 corners of the axis-aligned box [lo, hi] mapped by box_to_world.
inline std::array<Eigen::Vector3d, 8> BoxCorners(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                                 const Eigen::Isometry3d& box_to_world) {
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i) {
    corners[i] = box_to_world * Eigen::Vector3d(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  }
  return corners;
}

inline TriangleBatch Box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Isometry3d& box_to_world,
                         const Eigen::Vector3f& color) {
  const auto c = BoxCorners(lo, hi, box_to_world);
  // Faces by corner index (bit 0 = x, bit 1 = y, bit 2 = z); winding does not matter (no culling).
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  TriangleBatch batch;
  for (const auto& f : faces) {
    const Eigen::Vector3d quad[4] = {c[f[0]], c[f[1]], c[f[2]], c[f[3]]};
    AppendQuad(batch, quad, Eigen::Vector4f(0, 0, 1, 1), color);
  }
  return batch;
}

}  // namespace arview::render::testing
