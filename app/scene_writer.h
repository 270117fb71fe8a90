#pragma once
// Writes the scene file (the format of anim_authoring/scene.h) for a character placed by `arview place`:
// the anchor, and K look-at keys evenly spaced on the horizon around the character.

#include <filesystem>
#include <string>

#include "app/placement.h"

namespace arview::app {

struct PlacedCharacter {
  std::string name = "character";
  std::filesystem::path asset;  // absolute
  Anchor anchor;
  int key_count = 8;
  double key_elevation_deg = 0;  // of every key, above the character's horizon
  std::string base_clip;  // empty: the asset's first clip
  std::string comment;    // written at the top of the file
  double rest_height = 0; // the asset's rest-pose height, asset units (for messages)
};

std::string SceneYaml(const PlacedCharacter& character);

// Parses the text with anim's scene reader before writing (a file `arview place` wrote always
// loads), then writes atomically. Throws on either failure, naming the file.
void WriteSceneFile(const PlacedCharacter& character, const std::filesystem::path& file);

}  // namespace arview::app
