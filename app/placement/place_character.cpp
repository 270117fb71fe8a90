#include "app/placement/place_character.h"

#include <algorithm>
#include <cmath>

#include "anim_authoring/import.h"
#include "anim/character_bounds.h"
#include "base/stats.h"

namespace arview::app {

double MetricHeight(const PlaceCharacterOptions& o, double asset_height) {
  if (o.height_m) return *o.height_m;
  const bool plausible = asset_height >= kPlausibleAssetHeightMetres[0] && asset_height <= kPlausibleAssetHeightMetres[1];
  return plausible ? asset_height : kDefaultHeightMetres;
}

ScenePlacement PlaceCharacter(const map::Map& map, const std::filesystem::path& asset_path,
                               const PlaceCharacterOptions& o) {
  // A built-in asset ("builtin:figure") is a name, not a file.
  const std::filesystem::path asset =
      authoring::IsBuiltinAsset(asset_path) ? asset_path : std::filesystem::absolute(asset_path);
  const anim::Character character = authoring::LoadCharacter(asset);
  const double height = anim::RestHeight(character, Eigen::Vector3d::UnitY());
  // Named here, by the asset (a PlacementError is said of the map).
  if (!(height > 0)) throw Error(asset.string() + ": the character has no height (empty or flat bind pose)");

  std::vector<Eigen::Vector3d> points, centres, up_axes;
  points.reserve(map.points.size());
  for (const auto& p : map.points) points.push_back(p.xyz);
  // The first keyframe (lowest frame index) goes first: the character faces it.
  const map::Keyframe* first = nullptr;
  for (const auto& k : map.keyframes) {
    if (!first || k.frame_index < first->frame_index) first = &k;
  }
  if (first) centres.push_back(first->pose.Center());
  for (const auto& k : map.keyframes) {
    if (&k != first) centres.push_back(k.pose.Center());
    up_axes.push_back(-(k.pose.CameraToWorldRotation() * Eigen::Vector3d::UnitY()));
  }
  PlacementOptions options;
  options.height_fraction = o.height_fraction;
  options.plane.seed = o.seed;

  ScenePlacement placed;
  placed.name = authoring::IsBuiltinAsset(asset) ? asset.string().substr(std::string(authoring::kBuiltinAssetPrefix).size())
                                            : asset.stem().string();
  placed.asset = asset;
  placed.anchor = o.anchor ? *o.anchor : PlaceOnFloor(points, centres, up_axes, height, options);
  // A metric map says how tall in metres; otherwise the fraction of the viewing distance stands.
  if (!o.anchor && map.frame.metric()) placed.anchor.scale = MetricHeight(o, height) / height;
  placed.rest_height = height;
  // Keys on the ring the viewers actually occupy: at the median elevation of the map's cameras
  // seen from the character's eyes (a character on a table is looked at from above; a tall one
  // looks down at cameras held lower than its head). Eyes: 93% of the rest height.
  std::vector<double> elevations;
  const Eigen::Vector3d up = placed.anchor.rotation * Eigen::Vector3d::UnitY();
  const Eigen::Vector3d eyes = placed.anchor.position + 0.93 * height * placed.anchor.scale * up;
  for (const auto& c : centres) {
    const Eigen::Vector3d d = c - eyes;
    if (d.norm() > 0) elevations.push_back(std::asin(std::clamp(up.dot(d.normalized()), -1.0, 1.0)) * 180 / M_PI);
  }
  if (!elevations.empty() && o.key_elevation_deg.has_value() == false) {
    placed.key_elevation_deg = std::clamp(Median(elevations), -60.0, 60.0);
  } else {
    placed.key_elevation_deg = o.key_elevation_deg.value_or(0.0);
  }
  if (o.stand_at) placed.anchor = StandAt(placed.anchor, *o.stand_at, o.facing.value_or(centres.empty() ? *o.stand_at : centres.front()));
  placed.key_count = o.keys;
  placed.base_clip = o.base_clip;
  if (placed.base_clip.empty() && !character.clips.empty()) placed.base_clip = character.clips.front().name;
  return placed;
}

}  // namespace arview::app
