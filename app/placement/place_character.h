#pragma once
// `arview place` as a function (the demo calls it too): a character from an asset, standing on
// the dominant plane of a map, with look-at keys around it.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "app/placement/scene_writer.h"
#include "map/map.h"

namespace arview::app {

struct PlaceCharacterOptions {
  int keys = 8;
  double height_fraction = 0.3;  // of the median camera distance to the anchor
  std::string base_clip;         // empty: the asset's first clip; "rest": the rest pose
  std::optional<double> key_elevation_deg;  // empty: the median elevation of the map's cameras
  std::uint64_t seed = 1;
  // Given: the character stands here (position, rotation and scale in map units) instead of on
  // the dominant plane, e.g. where the demo's walk circles; the keys are still fitted to the
  // map's cameras.
  std::optional<Anchor> anchor;
};

ScenePlacement PlaceCharacter(const map::Map& map, const std::filesystem::path& asset,
                               const PlaceCharacterOptions& options);

}  // namespace arview::app
