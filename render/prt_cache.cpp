#include "render/prt_cache.h"

#include "base/cache_folder.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <string_view>
#include <system_error>

#include "base/atomic_file.h"
#include "base/error.h"
#include "base/hash.h"
#include "base/input_guard.h"

namespace arview::render {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "ARVPRT1\n";
// Bumped whenever ComputeShadowedTransfer's result changes for the same inputs.
constexpr std::uint64_t kTransferVersion = 1;
// Far above any character's transfer (25k vertices: 0.9 MB), far below a harmful allocation.
constexpr std::uintmax_t kMaxCacheFileBytes = 512ull << 20;

template <typename T>
void Append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Reads a T at `at`, advancing it; false when the bytes run out.
template <typename T>
bool Take(std::string_view bytes, std::size_t& at, T& value) {
  if (bytes.size() - at < sizeof(T)) return false;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  at += sizeof(T);
  return true;
}

std::string Serialize(std::uint64_t key, const CharacterTransfer& transfer) {
  std::string out(kMagic);
  Append(out, key);
  Append(out, static_cast<std::uint32_t>(transfer.meshes.size()));
  for (const auto& mesh : transfer.meshes) Append(out, static_cast<std::uint32_t>(mesh.size()));
  for (const auto& mesh : transfer.meshes) out.append(reinterpret_cast<const char*>(mesh.data()), mesh.size() * sizeof(Sh9f));
  Append(out, static_cast<std::int64_t>(transfer.rays));
  Append(out, transfer.occluded_share);
  Fnv1a checksum;
  checksum.Add(out.data(), out.size());
  Append(out, checksum.hash);
  return out;
}

// The transfer in `bytes` when they are a valid cache file for `key` and `character`; else the
// reason they are not.
bool Deserialize(std::string_view bytes, std::uint64_t key, const anim::Character& character,
                 CharacterTransfer& transfer, std::string& why) {
  if (bytes.size() < kMagic.size() + sizeof(std::uint64_t) || bytes.substr(0, kMagic.size()) != kMagic) {
    why = "not a PRT cache file";
    return false;
  }
  Fnv1a checksum;
  checksum.Add(bytes.data(), bytes.size() - sizeof(std::uint64_t));
  std::uint64_t stored_checksum = 0;
  std::memcpy(&stored_checksum, bytes.data() + bytes.size() - sizeof(std::uint64_t), sizeof(std::uint64_t));
  if (stored_checksum != checksum.hash) {
    why = "checksum mismatch";
    return false;
  }
  const std::string_view body = bytes.substr(0, bytes.size() - sizeof(std::uint64_t));
  std::size_t at = kMagic.size();
  std::uint64_t stored_key = 0;
  std::uint32_t mesh_count = 0;
  if (!Take(body, at, stored_key) || stored_key != key) {
    why = "made for another character or other options";
    return false;
  }
  if (!Take(body, at, mesh_count) || mesh_count != character.meshes.size()) {
    why = "mesh count differs";
    return false;
  }
  transfer.meshes.assign(mesh_count, {});
  for (std::uint32_t m = 0; m < mesh_count; ++m) {
    std::uint32_t vertices = 0;
    if (!Take(body, at, vertices) || vertices != static_cast<std::uint32_t>(character.meshes[m].vertex_count())) {
      why = "vertex count of mesh " + std::to_string(m) + " differs";
      return false;
    }
    transfer.meshes[m].resize(vertices);
  }
  for (auto& mesh : transfer.meshes) {
    const std::size_t size = mesh.size() * sizeof(Sh9f);
    if (body.size() - at < size) {
      why = "truncated";
      return false;
    }
    std::memcpy(mesh.data(), body.data() + at, size);
    at += size;
    for (const Sh9f& t : mesh)
      for (float c : t)
        if (!std::isfinite(c)) {
          why = "holds a non-finite value";
          return false;
        }
  }
  std::int64_t rays = 0;
  if (!Take(body, at, rays) || !Take(body, at, transfer.occluded_share) || at != body.size() || rays < 0 ||
      !(transfer.occluded_share >= 0 && transfer.occluded_share <= 1)) {
    why = "damaged trailer";
    return false;
  }
  transfer.rays = rays;
  return true;
}

std::string Hex(std::uint64_t key) {
  std::ostringstream s;
  s << std::hex << std::setw(16) << std::setfill('0') << key;
  return s.str();
}

}  // namespace

fs::path DefaultPrtCacheFolder() { return CacheFolder("prt"); }

std::uint64_t PrtCacheKey(const anim::Character& character, const PrtOptions& options) {
  Fnv1a h;
  h.AddValue(kTransferVersion);
  h.AddValue(options.directions);
  h.AddValue(options.min_hit_fraction);
  h.AddValue(options.skip_adjacent);
  h.AddValue(static_cast<std::uint64_t>(character.meshes.size()));
  for (const anim::Mesh& mesh : character.meshes) {
    h.AddValue(static_cast<std::uint64_t>(mesh.positions.size()));
    h.Add(mesh.positions.data(), mesh.positions.size() * sizeof(Eigen::Vector3f));
    h.AddValue(static_cast<std::uint64_t>(mesh.normals.size()));
    h.Add(mesh.normals.data(), mesh.normals.size() * sizeof(Eigen::Vector3f));
    h.AddValue(static_cast<std::uint64_t>(mesh.indices.size()));
    h.Add(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
  }
  return h.hash;
}

PrtCacheResult ShadowedTransferCached(const anim::Character& character, const PrtOptions& options,
                                      const fs::path& folder) {
  PrtCacheResult result;
  if (folder.empty()) {
    result.transfer = ComputeShadowedTransfer(character, options);
    return result;
  }
  const std::uint64_t key = PrtCacheKey(character, options);
  result.file = folder / (Hex(key) + ".prt");
  std::error_code ec;
  if (fs::exists(result.file, ec)) {
    const auto start = std::chrono::steady_clock::now();
    try {
      const std::string bytes = ReadFileUpTo(result.file, kMaxCacheFileBytes);
      std::string why;
      if (Deserialize(bytes, key, character, result.transfer, why)) {
        result.from_cache = true;
        result.transfer.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return result;
      }
      result.note = result.file.string() + ": " + why + "; computed again";
    } catch (const Error& e) {
      result.note = std::string(e.what()) + "; computed again";
    }
  }
  result.transfer = ComputeShadowedTransfer(character, options);
  try {
    fs::create_directories(folder, ec);
    if (ec) throw Error(folder.string() + ": cannot create the cache folder (" + ec.message() + ")");
    WriteFileAtomically(result.file, Serialize(key, result.transfer));
  } catch (const Error& e) {
    // Not fatal: the next run computes the transfer again.
    result.note += (result.note.empty() ? "" : "; ") + std::string(e.what()) + " (PRT not cached)";
  }
  return result;
}

}  // namespace arview::render
