#pragma once
// FNV-1a, 64-bit: a fast, non-cryptographic hash of bytes, for cache keys, file checksums and
// comparing outputs bit for bit. Header-only and allocation-free (the fuzz driver calls it from
// its crash handler). map/map_file.cpp's checksum is a word-wise variant fixed by its file
// format, and stays as it is.

#include <cstddef>
#include <cstdint>

namespace arview {

struct Fnv1a {
  std::uint64_t hash = 1469598103934665603ull;
  void Add(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 1099511628211ull;
  }
  template <typename T>
  void AddValue(const T& value) { Add(&value, sizeof(T)); }
};

inline std::uint64_t Fnv1aOf(const void* data, std::size_t size) {
  Fnv1a h;
  h.Add(data, size);
  return h.hash;
}

}  // namespace arview
