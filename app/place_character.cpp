#include "app/place_character.h"

#include "anim/character.h"
#include "app/character_bounds.h"

namespace arview::app {

PlacedCharacter PlaceCharacter(const mapping::Map& map, const std::filesystem::path& asset_path,
                               const PlaceCharacterOptions& o) {
  const std::filesystem::path asset = std::filesystem::absolute(asset_path);
  const anim::Character character = anim::LoadCharacter(asset);
  const double height = RestHeight(character, Eigen::Vector3d::UnitY());

  std::vector<Eigen::Vector3d> points, centres;
  points.reserve(map.points.size());
  for (const auto& p : map.points) points.push_back(p.xyz);
  // The first keyframe (lowest frame index) goes first: the character faces it.
  const mapping::Keyframe* first = nullptr;
  for (const auto& k : map.keyframes) {
    if (!first || k.frame_index < first->frame_index) first = &k;
  }
  if (first) centres.push_back(first->pose.Center());
  for (const auto& k : map.keyframes) {
    if (&k != first) centres.push_back(k.pose.Center());
  }
  PlacementOptions options;
  options.height_fraction = o.height_fraction;
  options.plane.seed = o.seed;

  PlacedCharacter placed;
  placed.name = asset.stem().string();
  placed.asset = asset;
  placed.anchor = PlaceOnDominantPlane(points, centres, height, options);
  placed.rest_height = height;
  placed.key_count = o.keys;
  placed.base_clip = o.base_clip;
  if (placed.base_clip.empty() && !character.clips.empty()) placed.base_clip = character.clips.front().name;
  return placed;
}

}  // namespace arview::app
