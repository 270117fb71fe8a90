#include "render/prt.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <thread>

#include "room/ray_caster.h"
#include <Eigen/Geometry>

namespace arview::render {

room::Sh9 UnshadowedTransfer(const Eigen::Vector3d& n) {
  const double band[3] = {M_PI, 2 * M_PI / 3, M_PI / 4};
  room::Sh9 t = room::ShBasis(n);
  for (int k = 0; k < 9; ++k) t[k] *= band[k == 0 ? 0 : (k < 4 ? 1 : 2)];
  return t;
}

CharacterTransfer ComputeShadowedTransfer(const anim::Character& character, const PrtOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CharacterTransfer out;
  // All segments in one triangle list; global vertex ids per mesh.
  std::vector<Eigen::Vector3f> corners;
  std::vector<int> mesh_first_vertex;
  int vertex_total = 0;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (const anim::Mesh& mesh : character.meshes) {
    mesh_first_vertex.push_back(vertex_total);
    vertex_total += mesh.vertex_count();
    for (const auto& p : mesh.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    for (std::uint32_t index : mesh.indices) corners.push_back(mesh.positions.at(index));
  }
  out.meshes.resize(character.meshes.size());
  if (vertex_total == 0) return out;
  const float diagonal = (hi - lo).norm();
  const float epsilon = static_cast<float>(options.min_hit_fraction) * diagonal;

  // Triangles around each vertex, shared between vertices at the same place (seams between
  // segments): the position quantised to a thousandth of ε.
  std::vector<std::vector<int>> skip(vertex_total);
  if (options.skip_adjacent) {
    const float quantum = std::max(epsilon * 1e-3f, 1e-9f);
    auto key = [&](const Eigen::Vector3f& p) {
      return std::array<long long, 3>{std::llround(p.x() / quantum), std::llround(p.y() / quantum), std::llround(p.z() / quantum)};
    };
    std::map<std::array<long long, 3>, std::vector<int>> around;
    int triangle = 0;
    for (const anim::Mesh& mesh : character.meshes)
      for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3, ++triangle)
        for (int k = 0; k < 3; ++k) around[key(mesh.positions[mesh.indices[i + k]])].push_back(triangle);
    for (size_t m = 0; m < character.meshes.size(); ++m) {
      const anim::Mesh& mesh = character.meshes[m];
      for (int v = 0; v < mesh.vertex_count(); ++v) {
        std::vector<int>& s = skip[mesh_first_vertex[m] + v];
        s = around[key(mesh.positions[v])];
        std::sort(s.begin(), s.end());
        s.erase(std::unique(s.begin(), s.end()), s.end());
      }
    }
  }
  const room::TriangleBvh bvh(std::move(corners));

  std::vector<Eigen::Vector3f> directions(options.directions);
  std::vector<room::Sh9> basis(options.directions);
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int i = 0; i < options.directions; ++i) {
    const double z = 1 - (2 * i + 1.0) / options.directions;
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Eigen::Vector3d d(r * std::cos(golden * i), r * std::sin(golden * i), z);
    directions[i] = d.cast<float>();
    basis[i] = room::ShBasis(d);
  }
  const double weight = 4 * M_PI / options.directions;

  std::vector<std::pair<int, int>> work;  // (mesh, vertex)
  for (size_t m = 0; m < character.meshes.size(); ++m) {
    out.meshes[m].resize(character.meshes[m].vertex_count());
    for (int v = 0; v < character.meshes[m].vertex_count(); ++v) work.emplace_back(static_cast<int>(m), v);
  }
  std::atomic<long long> rays{0}, occluded{0};
  std::atomic<size_t> next{0};
  auto worker = [&] {
    long long my_rays = 0, my_occluded = 0;
    for (size_t w; (w = next.fetch_add(1)) < work.size();) {
      const auto [m, v] = work[w];
      const anim::Mesh& mesh = character.meshes[m];
      const Eigen::Vector3f p = mesh.positions[v];
      Eigen::Vector3f n = mesh.normals[v];
      if (n.norm() < 1e-6f) n = Eigen::Vector3f::UnitY();
      n.normalize();
      room::Sh9 t = UnshadowedTransfer(n.cast<double>());
      const std::vector<int>& s = skip[mesh_first_vertex[m] + v];
      for (int i = 0; i < options.directions; ++i) {
        const float c = n.dot(directions[i]);
        if (c <= 0) continue;
        ++my_rays;
        if (!bvh.Occluded(p, directions[i], epsilon, 1e30f, s)) continue;
        ++my_occluded;
        for (int k = 0; k < 9; ++k) t[k] -= c * basis[i][k] * weight;
      }
      for (int k = 0; k < 9; ++k) out.meshes[m][v][k] = static_cast<float>(t[k]);
    }
    rays += my_rays;
    occluded += my_occluded;
  };
  const int threads = std::max(1, options.threads);
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  out.rays = rays;
  out.occluded_share = rays > 0 ? double(occluded) / double(rays) : 0;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace arview::render
