// arview place: put a character on the dominant plane of a map and write its scene file.

#include <cstdio>

#include "anim_authoring/import.h"
#include "app/cli/commands.h"
#include "app/placement/place_character.h"
#include "app/placement/scene_lighting.h"
#include "map/map_file.h"

namespace arview::app {

namespace {

struct PlaceArgs {
  std::string map_dir;
  std::string character;
  std::string out;
  PlaceCharacterOptions options;
  std::optional<double> elevation;
  std::optional<double> height;
  std::string recording;  // where still keyframe images are (video maps keep theirs in <map>/images)
  bool no_light = false;
  std::vector<double> at, facing;  // x,y,z in map units, or empty
};

std::optional<Eigen::Vector3d> PointOrNone(const std::vector<double>& xyz) {
  if (xyz.size() != 3) return std::nullopt;
  return Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
}

// A --base-clip the asset lacks is refused before the map is read and before a scene naming it
// is written (the scene would only fail when loaded, far from the command that made it).
void RequireBaseClip(const std::string& asset, const std::string& clip) {
  if (clip.empty() || clip == "rest") return;
  const anim::Character character = authoring::LoadCharacter(asset);
  std::string names;
  for (const auto& c : character.clips) {
    if (c.name == clip) return;
    names += (names.empty() ? "" : ", ") + c.name;
  }
  throw CommandError("--base-clip: '" + clip + "' is not a clip of " + asset + " (clips: " +
                     (names.empty() ? "none; use 'rest'" : names + ", or 'rest'") + ")");
}

}  // namespace

void AddPlaceCommand(CLI::App& app) {
  auto a = std::make_shared<PlaceArgs>();
  auto* cmd = app.add_subcommand("place", "Place a character on the dominant plane of a map and write a scene file");
  cmd->add_option("map-dir", a->map_dir, "Map folder written by 'arview map'")->required();
  cmd->add_option("--character", a->character, "Character asset (glTF, FBX, Collada, .X, BVH)")->required();
  cmd->add_option("--out", a->out, "Scene file to write (YAML)")->required();
  cmd->add_option("--keys", a->options.keys, "Look-at key animations generated around the character")
      ->capture_default_str()
      ->check(CLI::Range(2, 64));
  cmd->add_option("--height", a->height,
                  "Character height: metres on a metric map (default: the asset's own height when it is 0.1-2.5, "
                  "glTF's metres, else 1.7), on a map without scale a fraction of the median camera distance to it "
                  "(default 0.3); 'arview map info' says which the map is")
      ->check(CLI::Range(0.001, 10.0));
  cmd->add_option("--base-clip", a->options.base_clip,
                  "Clip the look-at keys are built on, or 'rest' for the rest pose (default: the first clip)");
  cmd->add_option("--elevation", a->elevation,
                  "Elevation of the keys in degrees (default: the median elevation of the map's cameras)")
      ->check(CLI::Range(-89.0, 89.0));
  cmd->add_option("--seed", a->options.seed, "Seed of the plane RANSAC")->capture_default_str();
  cmd->add_option("--recording", a->recording,
                  "Recording the map was built from, for its keyframe images (the room's light; video maps need none)");
  cmd->add_option("--at", a->at,
                  "x,y,z in map units: stand the character on the floor where this point falls instead of the "
                  "floor's middle ('arview run' without --scene prints the --at and --facing that keep its figure)")
      ->expected(3)
      ->delimiter(',');
  cmd->add_option("--facing", a->facing, "x,y,z in map units: the point the character faces (default: the first keyframe)")
      ->expected(3)
      ->delimiter(',');
  cmd->add_flag("--no-light", a->no_light, "Do not estimate the room's light (no <scene>.light.yml)");
  cmd->callback([a] {
    if (a->elevation) a->options.key_elevation_deg = *a->elevation;
    a->options.stand_at = PointOrNone(a->at);
    a->options.facing = PointOrNone(a->facing);
    if (a->options.facing && !a->options.stand_at) throw CommandError("--facing needs --at (where the character stands)");
    RequireBaseClip(a->character, a->options.base_clip);
    const map::Map map = map::LoadMap(a->map_dir);
    if (map.frame.metric()) {
      a->options.height_m = a->height;
    } else if (a->height) {
      a->options.height_fraction = *a->height;
    }
    // Said of the map folder: the plane fit alone said "no floor-like plane ... holds 3 or more
    // of the map's points" of a map whose points were all at one spot.
    if (const auto why = map::DegeneratePoints(map)) {
      throw CommandError(a->map_dir + ": the map's points cannot hold a floor: " + *why);
    }
    ScenePlacement placed = [&] {
      try {
        return PlaceCharacter(map, a->character, a->options);
      } catch (const PlacementError& e) {
        throw CommandError(a->map_dir + ": " + e.what());
      }
    }();
    placed.comment = "character " + placed.asset.filename().string() + " on the dominant plane of " + a->map_dir;
    WriteSceneFile(placed, a->out);
    const Anchor& anchor = placed.anchor;
    const Eigen::Vector3d up = anchor.rotation * Eigen::Vector3d::UnitY();
    std::printf("placed %s at (%.4f, %.4f, %.4f), up (%.3f, %.3f, %.3f), scale %.5g (rest height %.4g units)\n",
                placed.name.c_str(), anchor.position.x(), anchor.position.y(), anchor.position.z(),
                up.x(), up.y(), up.z(), anchor.scale, placed.rest_height);
    if (map.frame.metric()) {
      std::printf("%.2f m tall (the map is in metres, from %s%s)\n", anchor.scale * placed.rest_height,
                  map::ToString(map.frame.scale_source),
                  map.frame.scale_source == map::ScaleSource::kCameraHeight ? ": an estimate" : "");
    } else {
      std::printf("%.3g of the median camera distance tall (the map has no scale: 'arview map scale' gives it one)\n",
                  a->options.height_fraction);
    }
    std::printf("wrote %s with %d look-at keys at %.1f deg elevation\n", a->out.c_str(), placed.key_count,
                placed.key_elevation_deg);
    if (!a->no_light) WritePlacedLight(map, a->map_dir, a->recording, placed, a->out);
  });
}

}  // namespace arview::app
