#pragma once
// Key-camera authoring (the self-adaptive paper §3.2): the author moves the camera and adds a
// key there, tied to a clip, a static pose or a generated key type; removes the key nearest to
// the current viewpoint; undoes; and writes the scene back.
//
// Writing edits the scene file in place: only the edited character's `keys:` block changes, and
// keys that were in the file keep their text (comments included), so everything else the author
// wrote (other characters, schedules, comments) is kept as written. The new text is re-read by
// anim's scene reader and checked to hold exactly the edited keys before it atomically replaces
// the file.

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "anim/character.h"
#include "anim_authoring/scene.h"

namespace arview::app {

// What a new key plays.
struct KeyChoice {
  authoring::KeySpec::Source source = authoring::KeySpec::Source::kClip;
  std::string clip;             // kClip; kStaticPose: the clip frozen at the time of adding
  std::string label;            // "clip Survey", "pose rest", "pose Walk@now", "generate lookat"
};

// Every clip, a frozen frame of every clip, the rest pose, and the generated key types.
std::vector<KeyChoice> KeyChoices(const anim::Character& asset);

// A key for `viewpoint` (character frame) playing `choice`; a static pose freezes the clip at
// `time` (seconds, wrapped into the clip, rounded to 0.01 s). The key's azimuth and elevation in
// the frame of `spec`'s forward and up are rounded to 0.01°, so the file says exactly what is
// played.
authoring::KeySpec MakeKey(const Eigen::Vector3d& viewpoint, const KeyChoice& choice, const anim::Character& asset,
                      const authoring::CharacterSpec& spec, double time);

// Azimuth and elevation (degrees) of a direction in the frame of `forward` and `up`, as the
// scene format measures them.
Eigen::Vector2d AzimuthElevation(const Eigen::Vector3d& direction, const Eigen::Vector3d& forward,
                                 const Eigen::Vector3d& up);

// The keys of one character and their history.
class KeyEditor {
 public:
  explicit KeyEditor(std::vector<authoring::KeySpec> keys = {});

  const std::vector<authoring::KeySpec>& keys() const { return keys_; }
  // Each key's index among the keys of the scene file as last read or written, or -1 for a key
  // added since.
  std::vector<int> FileOrigins() const;
  bool dirty() const { return keys_ids_ != saved_ids_; }
  bool can_undo() const { return !history_.empty(); }

  void Add(const authoring::KeySpec& key);
  // Throws std::runtime_error if it would leave no key (a character needs one).
  void Remove(int index);
  // Restores the keys before the last Add/Remove; false if there is nothing to undo.
  bool Undo();
  // The keys now in the file are the current ones.
  void MarkSaved();

  // The key whose viewpoint is nearest (by angle) to `viewpoint`.
  int Nearest(const Eigen::Vector3d& viewpoint) const;

 private:
  struct Snapshot {
    std::vector<authoring::KeySpec> keys;
    std::vector<int> ids;
  };
  std::vector<authoring::KeySpec> keys_;
  std::vector<int> keys_ids_;   // a unique id per key, kept by undo
  std::vector<int> saved_ids_;  // ids of the keys in the file, in file order
  std::vector<Snapshot> history_;
  int next_id_ = 0;
};

// The scene text with the keys block of character `character` (its index in `scene`, parsed
// from `text`) holding `keys`; `origins[i]` >= 0 keeps the text of that key of the file.
// Throws std::runtime_error naming the file when the block cannot be found in block style.
std::string SpliceKeys(const std::string& text, const authoring::Scene& scene, int character,
                       const std::vector<authoring::KeySpec>& keys, const std::vector<int>& origins);

// Re-reads `text` with anim's scene reader and checks that character `character` has exactly
// `keys` (directions within 1e-6 rad, same sources). Throws naming the file.
authoring::Scene ValidateSceneText(const std::string& text, const std::filesystem::path& file, int character,
                              const std::vector<authoring::KeySpec>& keys);

}  // namespace arview::app
