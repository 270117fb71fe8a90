#pragma once
// The glTF container as gltf_check.cpp reads it before checking its structure: the file's bytes
// (bounded), the GLB header and chunks, the JSON (bounded depth), data URIs (percent-encoding and
// base64). Internal to anim_authoring.

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace arview::authoring::gltf {

inline constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
inline constexpr std::uintmax_t kMaxAssetBytes = 1ull << 30;  // BrainStem.glb, the largest we use, is 3 MB

// The little-endian 32-bit word at `at` (the caller has checked there are 4 bytes).
std::uint32_t ReadU32(std::string_view bytes, std::size_t at);
std::string ToLower(std::string s);
// A URI's percent-encoding decoded.
std::string DecodeUri(const std::string& uri);
// Standard base64 (padding optional); nothing for text that is not base64.
std::optional<std::string> DecodeBase64(std::string_view text);
// The JSON document, at most kMaxJsonDepth levels deep; throws anim::Error naming `file`.
nlohmann::json ParseJson(const std::filesystem::path& file, std::string_view text);

struct GlbChunks {
  std::string_view json, bin;
  bool has_bin = false;
};
// The GLB container: header, then chunks of (length, type, data), each inside the file; throws
// anim::Error naming `file` and the chunk.
GlbChunks SplitGlb(const std::filesystem::path& file, std::string_view bytes);
// The whole file, at most 1 GiB; throws anim::Error.
std::string ReadAsset(const std::filesystem::path& file);

}  // namespace arview::authoring::gltf
