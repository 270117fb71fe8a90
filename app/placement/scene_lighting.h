#pragma once
// The room's light of a scene (issue 14): estimated at `arview place` from the map's keyframes
// and stored beside the scene file (scene.yaml → scene.light.yml), read by `arview render`,
// `replay` and `run` for the SH / PRT lighting, the cast shadow and the occluders.

#include <filesystem>
#include <optional>
#include <string>

#include "app/placement/scene_writer.h"
#include "map/map.h"
#include "render/character_renderer.h"
#include "room/room_light.h"

namespace arview::app {

// scene.yaml → scene.light.yml (same folder).
std::filesystem::path LightFileFor(const std::filesystem::path& scene_file);

struct PlacedLightReport {
  room::RoomLight light;
  int keyframes_used = 0;
  int proxy_patches = 0;
  int occluder_triangles = 0;
  double proxy_seconds = 0;
};

// The light at the placed character's middle (half its height above the anchor, along its up),
// from up to `max_keyframes` of the map's keyframes (evenly spread) whose images are found in
// <map-dir>/images/ (video maps) or under `recording_root` (image recordings). The proxy is
// fitted to the map's points; the occluders are the proxy without the character's floor.
// Returns nothing when no keyframe image can be found; throws Error for an unreadable one.
std::optional<PlacedLightReport> EstimatePlacedLight(const map::Map& map, const std::filesystem::path& map_dir,
                                                     const std::filesystem::path& recording_root,
                                                     const ScenePlacement& placed, int max_keyframes = 60);

// `arview place`'s light step: estimates, writes LightFileFor(scene_file) and prints what it
// found (or why there is no light: no keyframe images).
void WritePlacedLight(const map::Map& map, const std::filesystem::path& map_dir,
                      const std::filesystem::path& recording_root, const ScenePlacement& placed,
                      const std::filesystem::path& scene_file);

// --lighting auto|fixed|sh|prt and --light FILE: auto is prt when the scene's light file (or
// `light_file`) exists, else fixed; sh/prt without a light file is an error naming the file.
struct SceneLighting {
  render::LightingMode mode = render::LightingMode::kFixed;
  std::optional<room::RoomLight> light;
  std::filesystem::path file;
};
SceneLighting ResolveSceneLighting(const std::filesystem::path& scene_file, const std::string& lighting,
                                   const std::filesystem::path& light_file);

}  // namespace arview::app
