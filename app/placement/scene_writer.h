#pragma once
// Writes the scene file (the format of anim_authoring/scene.h) for a character placed by `arview place`:
// the anchor, K look-at keys evenly spaced on the horizon around the character, and optionally
// its behaviour (idle synthesizer, a greeting when the viewer comes close).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "app/placement/placement.h"

namespace arview::app {

// What the character does besides the view-adaptive look-at (the scene's `idle:` and
// `schedule:` sections, docs/anim.md). Empty: the default schedule (the base clip looped under
// the view-adaptive blend).
struct PlacedBehaviour {
  // The idle synthesizer learns from these clips of the asset; it runs underneath, and the
  // view-adaptive blend then covers the body's turn (the root's rotation), the spine, neck and
  // head only (the arms, the legs and the weight shifts idle).
  std::vector<std::string> idle_clips;
  std::uint64_t idle_seed = 1;
  // A clip played once, on `greet_scope`, when the viewer comes within `greet_within` (map
  // units; 0: no greeting), re-armed beyond 1.4 times that.
  std::string greet_clip;
  double greet_within = 0;
  std::string greet_scope = "right_arm";
  // Keys within `gesture_within_deg` of the character's front get this gesture (`point` or
  // `reach`, anim_authoring/gesture.h): the right arm points at a viewer in front; the view
  // layer then covers the right arm too. Empty: look-at keys only.
  std::string front_gesture;
  double gesture_within_deg = 50;
  // Tracking loss: the view-adaptive blend holds for `loss_hold` s, then fades out (cosine)
  // over `loss_fade` s, and back on relocalization.
  double loss_hold = 0.5, loss_fade = 1.0;
  // What the character says (the scene's `lines:`, docs/speech.md): each line's cue (start, near,
  // behind, lost, found) and its markup.
  struct Line {
    std::string when;
    std::string say;
  };
  std::vector<Line> lines;

  bool empty() const { return idle_clips.empty() && greet_clip.empty() && front_gesture.empty() && lines.empty(); }
};

struct ScenePlacement {
  std::string name = "character";
  std::filesystem::path asset;  // absolute
  Anchor anchor;
  int key_count = 8;
  double key_elevation_deg = 0;  // of every key, above the character's horizon
  std::string base_clip;  // empty: the asset's first clip
  std::string comment;    // written at the top of the file
  double rest_height = 0; // the asset's rest-pose height, asset units (for messages)
  PlacedBehaviour behaviour;
};

std::string SceneYaml(const ScenePlacement& character);

// Parses the text with anim's scene reader before writing (a file `arview place` wrote always
// loads), then writes atomically. Throws on either failure, naming the file.
void WriteSceneFile(const ScenePlacement& character, const std::filesystem::path& file);

}  // namespace arview::app
