#include "anim_authoring/gltf_container.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>

#include "anim/character.h"
#include "base/input_guard.h"

namespace arview::authoring::gltf {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr int kMaxJsonDepth = 64;
constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

struct TooDeep {};

}  // namespace

std::uint32_t ReadU32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);  // glTF is little-endian, as this machine
  return v;
}

std::string ToLower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// %XX escapes of a URI decoded (a file name with a space is written "a%20b.bin").
std::string DecodeUri(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

std::optional<std::string> DecodeBase64(std::string_view text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+' || c == '-') return 62;
    if (c == '/' || c == '_') return 63;
    return -1;
  };
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    const int v = value(c);
    if (v < 0) return std::nullopt;
    bits = (bits << 6) | static_cast<std::uint32_t>(v);
    if (++count == 4) {
      out += static_cast<char>(bits >> 16);
      out += static_cast<char>(bits >> 8);
      out += static_cast<char>(bits);
      bits = 0;
      count = 0;
    }
  }
  if (count == 1) return std::nullopt;
  if (count == 2) out += static_cast<char>(bits >> 4);
  if (count == 3) {
    out += static_cast<char>(bits >> 10);
    out += static_cast<char>(bits >> 2);
  }
  return out;
}

json ParseJson(const fs::path& file, std::string_view text) {
  const json::parser_callback_t depth_limit = [](int depth, json::parse_event_t, json&) {
    if (depth > kMaxJsonDepth) throw TooDeep{};
    return true;
  };
  try {
    return json::parse(text.begin(), text.end(), depth_limit);
  } catch (const TooDeep&) {
    throw anim::Error(file.string() + ": the glTF JSON is nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  } catch (const json::exception& e) {
    throw anim::Error(file.string() + ": the glTF JSON does not parse: " + e.what());
  }
}

GlbChunks SplitGlb(const fs::path& file, std::string_view bytes) {
  auto fail = [&](const std::string& what) { throw anim::Error(file.string() + ": " + what); };
  if (bytes.size() < 20) fail("a GLB file shorter than its 12-byte header and first chunk header");
  if (ReadU32(bytes, 4) != 2) fail("GLB version " + std::to_string(ReadU32(bytes, 4)) + " is not 2");
  if (ReadU32(bytes, 8) != bytes.size())
    fail("the GLB header gives a length of " + std::to_string(ReadU32(bytes, 8)) + " bytes, the file has " +
         std::to_string(bytes.size()));
  GlbChunks chunks;
  std::size_t at = 12;
  for (int index = 0; at < bytes.size(); ++index) {
    if (bytes.size() - at < 8) fail("GLB chunk " + std::to_string(index) + " at byte " + std::to_string(at) + " is cut off");
    const std::uint64_t length = ReadU32(bytes, at);
    const std::uint32_t type = ReadU32(bytes, at + 4);
    if (length > bytes.size() - at - 8)
      fail("GLB chunk " + std::to_string(index) + " at byte " + std::to_string(at) + " says " + std::to_string(length) +
           " bytes, only " + std::to_string(bytes.size() - at - 8) + " follow");
    if (length % 4 != 0) fail("GLB chunk " + std::to_string(index) + "'s length " + std::to_string(length) + " is not a multiple of 4");
    const std::string_view data = bytes.substr(at + 8, length);
    if (index == 0) {
      if (type != kChunkJson) fail("the first GLB chunk is not JSON");
      chunks.json = data;
    } else if (type == kChunkJson) {
      fail("a second JSON chunk in the GLB");
    } else if (type == kChunkBin) {
      if (chunks.has_bin || index != 1) fail("a BIN chunk that is not the GLB's second chunk");
      chunks.bin = data;
      chunks.has_bin = true;
    }
    at += 8 + length;
  }
  return chunks;
}

std::string ReadAsset(const fs::path& file) {
  try {
    std::string bytes = ReadFileUpTo(file, kMaxAssetBytes);
    return bytes;
  } catch (const InputError& e) {
    throw anim::Error(e.what());
  }
}

}  // namespace arview::authoring::gltf
