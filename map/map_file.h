#pragma once
// The compact map file (<map-dir>/map.arvmap): one versioned, checksummed binary file holding
// the whole Map, read back without recomputation.
//
// Layout (little-endian): magic "ARVMAP\r\n" (8 bytes), uint32 version, uint32 reserved (0),
// uint64 payload size, uint64 payload checksum (64-bit FNV-1a over 8-byte words, tail bytes
// one by one), then the payload: camera (version 2: with its focus), keyframes (with their observations), points,
// descriptor rows, descriptor → point, descriptor → keyframe, and (version 2) the map's frame:
// scale source, z-up, scale error, its one-line description, COLMAP → map similarity, and
// (version 3) the rooms: their count and names, then each keyframe's room (int32, -1: none).
// Every count and index is checked on load; any mismatch throws MapError naming the file.
// Version 1 files (no frame record) load as COLMAP's frame, versions 1 and 2 without rooms.

#include <filesystem>
#include <optional>
#include <string>

#include "map/map.h"

namespace arview::map {

inline constexpr const char* kMapFileName = "map.arvmap";
inline constexpr std::uint32_t kMapFileVersion = 3;

// Writes atomically (a temporary file renamed into place). Throws MapError.
void SaveMap(const Map& map, const std::filesystem::path& file);

// `path` is the map file or a map directory holding map.arvmap. Throws MapError.
Map LoadMap(const std::filesystem::path& path);

// Checks the internal consistency of a Map (indices in range, row counts, observations);
// throws MapError prefixed with `source`.
void ValidateMap(const Map& map, const std::string& source);

// The value limits ValidateMap applies (mapping/ checks COLMAP's model against the same ones, so
// that a value out of range is reported against the COLMAP file that holds it).
inline constexpr double kMaxCoordinate = 1e6;  // map units: far beyond any mapped room or square
inline constexpr float kMaxPixel = 1e6f;

// Why the map's points cannot hold a floor (base/geometry.h WhyNotAPlane: all at one point, on
// one line, spread below 1e-100 map units, not finite), or nothing. `arview place` refuses such
// a map and `arview map info` warns about it.
std::optional<std::string> DegeneratePoints(const Map& map);

struct MapStats {
  std::size_t keyframes = 0;
  std::size_t points = 0;
  std::size_t descriptors = 0;
  std::size_t observations = 0;
  double mean_track_length = 0;
  // Mean and median distance between each observation and its point projected through the
  // keyframe's pose and the map's camera, in pixels (computed, not COLMAP's stored value).
  double mean_reprojection_error = 0;
  double median_reprojection_error = 0;
  double mean_colmap_point_error = 0;  // mean of COLMAP's per-point errors
};

MapStats ComputeStats(const Map& map);

}  // namespace arview::map
