#pragma once
// `arview place` as a function (the demo calls it too): a character from an asset, standing on
// the floor of a map (its lowest dense plane), with look-at keys around it.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "app/placement/scene_writer.h"
#include "map/map.h"

namespace arview::app {

// A character's height on a metric map when neither the user nor the asset says one: a person's.
inline constexpr double kDefaultHeightMetres = 1.7;
// An asset this tall or shorter, in its own units, is taken to be in metres (glTF's unit).
inline constexpr double kPlausibleAssetHeightMetres[2] = {0.1, 2.5};

struct PlaceCharacterOptions {
  int keys = 8;
  // The character's height. On a metric map (map.frame.metric()): `height_m` metres, and unset,
  // the asset's own height when it is a plausible one in metres (glTF's unit) or else
  // kDefaultHeightMetres. On a map without scale: `height_fraction` of the median camera
  // distance to the anchor.
  std::optional<double> height_m;
  double height_fraction = 0.3;
  std::string base_clip;         // empty: the asset's first clip; "rest": the rest pose
  std::optional<double> key_elevation_deg;  // empty: the median elevation of the map's cameras
  std::uint64_t seed = 1;
  // Given: the character stands here (position, rotation and scale in map units) instead of on
  // the floor found, e.g. where the demo's walk circles; the keys are still fitted to the
  // map's cameras.
  std::optional<Anchor> anchor;
  // Given: the character then moves on its floor to stand where `stand_at` (map units) falls on
  // it, facing `facing` (default: the first keyframe), its scale and keys unchanged (StandAt):
  // `arview place --at --facing`, and what `run` without --scene says to keep its figure.
  std::optional<Eigen::Vector3d> stand_at, facing;
};

// The height in metres a character of `asset_height` (its own units) gets on a metric map.
double MetricHeight(const PlaceCharacterOptions& options, double asset_height);

ScenePlacement PlaceCharacter(const map::Map& map, const std::filesystem::path& asset,
                               const PlaceCharacterOptions& options);

}  // namespace arview::app
