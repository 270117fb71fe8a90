#pragma once
// Scene files (YAML) describing view-adaptive characters: the reader (scene_reader.cpp). The
// characters are built from them by character_builder.h, their animators by animator_builder.h.
//
//   Scene scene = LoadScene("scene.yaml");               // throws anim::Error (file:line: why)
//   const CharacterSpec& spec = scene.characters[0];
//   AnimatedCharacter fox(spec);                          // character_builder.h: the asset, the keys
//   anim::Placement placement = spec.placement();         // where it stands in the map
//
// The scene format (paths are relative to the scene file; angles in degrees):
//
//   characters:
//     - name: fox
//       asset: ../shared/data/characters/Fox/glTF-Binary/Fox.glb
//       scale: 0.01                 # asset units → metres
//       anchor:                     # character frame → map frame
//         position: [0, 0, 0]
//         rotation: [0, 0, 0, 1]    # quaternion x y z w (or rotation_deg: [rx, ry, rz], XYZ)
//         scale: 1
//       forward: [0, 0, 1]          # the character's front in model space (default +Z)
//       up: [0, 1, 0]               # default +Y
//       weights: {mode: inverse-distance | local, distance: geodesic | chordal, alpha: 3}
//       blend: {method: dlb | dib, precision: 0.001, max_iterations: 32}
//       phase: shared | independent  # key clips on one normalised phase (default) or own loops
//       sampling: slerp | nlerp      # rotation interpolation between clip keys (default slerp)
//       lookat:                      # for keys with `generate: lookat`
//         base_clip: Survey
//         chain: [b_Spine01_02, b_Spine02_03, b_Neck_04, b_Head_05]  # default: found by name
//         limits: [45, 45, 50, 70]   # per joint, degrees (default 45 per spine joint, 50 neck, 70 head)
//       gesture:                     # for keys with `gesture: point | reach` (see gesture.h)
//         arm: right                 # or left
//         chain: [RightArm, RightForeArm, RightHand]  # upper arm, forearm, hand; default: found by name
//         elbow: [0, 150]            # elbow bend range, degrees (0 = straight)
//         shoulder_cone: 100         # half-angle about front-and-out, degrees
//         bend: {point: 10, reach: 40}  # elbow bend the gesture aims for, degrees
//       keys:
//         - viewpoint: [0, 0, 1]     # or azimuth: 0 with elevation: 0
//           clip: Survey             # a clip of the asset ...
//         - azimuth: 90
//           generate: lookat         # ... or generated (see lookat.h) ...
//         - azimuth: 30
//           gesture: point           # ... or a look-at key with the arm pointing along the viewpoint ...
//         - azimuth: 180
//           pose: rest               # ... or a static pose: rest, or "<clip>@<seconds>"
//       gaze:                        # eyes and lids (anim/gaze.h); only characters with eye joints
//         enabled: true              # default true
//         mode: listening            # listening | talking | rest (Eyes Alive's statistics)
//         blink_rate: 26             # per minute; default 17 at rest, 26 listening or talking
//         eye_range: {sideways: 35, up: 20, down: 25}   # degrees about the head's forward
//         seed: 1
//       voice: slt                   # Flite's voice for the lines: slt | rms | awb (checked by the session)
//       lines:                       # what the character says, and when (docs/speech.md, "Lines in scenes")
//         - when: start              # start | near | behind | lost | found
//           say: '<gesture name="Wave"/>Hello there!'   # the markup (speech/markup.h)
//         - when: near
//           near: 1.2                # metres; far: default 1.25·near + 0.1
//           say: Come closer.
//
// Flow mappings `{a: 1}` and flow sequences `[1, 2]` of scalars are accepted; see yaml.h.

#include "anim/character.h"
#include "anim/placement.h"
#include "anim_authoring/import.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/lookat.h"
#include "base/enum_table.h"
#include "speech/line_cue.h"
#include "base/geometry.h"
#include "anim/pose.h"
#include "anim/animator.h"
#include "anim/blending_params.h"
#include "anim/gaze.h"
#include "anim/idle.h"
#include "anim/view_adaptive.h"
#include "anim/view_sphere.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace arview::authoring {

// The scene file's anchor is the one arview::Anchor (base/geometry.h): the rotation a unit
// quaternion, as the placement that writes it.
using Anchor = arview::Anchor;

struct KeySpec {
  enum class Source { kClip, kLookAt, kRestPose, kStaticPose };
  // Names for messages and `arview anim weights` (base/enum_table.h), found by argument lookup.
  friend constexpr auto EnumNames(Source) {
    return EnumTable<Source, 4>{{{Source::kClip, "clip"},
                                 {Source::kLookAt, "lookat"},
                                 {Source::kRestPose, "rest"},
                                 {Source::kStaticPose, "pose"}}};
  }
  Eigen::Vector3d viewpoint = Eigen::Vector3d::UnitZ();  // unit, character frame
  Source source = Source::kClip;
  std::string clip;        // kClip, kStaticPose
  double pose_time = 0;    // kStaticPose
  Gesture gesture = Gesture::kNone;  // kLookAt: the arm on top points or reaches (gesture.h)
  int line = 0;            // where it was written, for messages
};

// The `schedule:` section (anim/schedule.h): actions on objects, with curves, masks, layers.
struct ActionSpec;
struct ObjectSpec {
  enum class Kind { kClip, kPose, kViewAdaptive, kIdle, kSchedule };
  Kind kind = Kind::kClip;
  std::string clip;          // kClip, kPose (empty with kPose: the rest pose)
  double pose_time = 0;      // kPose
  std::vector<ActionSpec> actions;  // kSchedule (nested)
  // Modifiers, applied in this order: window, stretch, loop, mirror, transform.
  bool has_window = false;
  double window_from = 0, window_to = 0;
  double stretch = 0;        // seconds; 0: none
  int loop = -1;             // −1: none, 0: forever, n: n times
  bool mirror = false;
  bool has_transform = false;
  Anchor transform;          // position + rotation (scale ignored)
  int line = 0;
};
struct MaskSpec {
  double default_rotation = 1, default_translation = 1;
  struct Scope {
    std::string name;
    double rotation = 1, translation = 1;
  };
  std::vector<Scope> scopes;  // applied in order over the default
  int line = 0;
};
struct ActionSpec {
  std::string name;
  ObjectSpec object;
  double start = 0;
  bool keep_rendering = false;
  int layer = 0;
  double weight = 1;
  std::vector<anim::Curve> curves, scalings;
  std::vector<MaskSpec> masks;
  bool has_trigger = false;  // a distance trigger: added when the viewer comes within `near`
  double trigger_near = 0, trigger_far = 0;
  std::vector<std::pair<double, double>> distance_weight;  // (metres, weight)
  int line = 0;
};
struct ScheduleSpec {
  bool given = false;        // false: the default (idle underneath, view-adaptive on top)
  std::vector<ActionSpec> actions;
  double rest_threshold = 0.1;
  double hold_seconds = 0.5, fade_seconds = 1.0;  // tracking loss
  std::string view_action = "view";
};
// The balance-shift layer (anim/balance_shift.h) under the idle synthesizer's variations,
// learned at load from one recording of a person standing (anim_authoring/balance.h).
struct BalanceSpec {
  bool given = false;
  std::filesystem::path motion;  // a recording (every clip of it), absolute; or
  std::string clip;              // a clip of the character itself
  std::uint64_t seed = 1;
  int components = 10;           // of the idle PCA, in the distance between postures
  int line = 0;
};

// The idle synthesizer (anim/idle.h), learned at load from motion files and/or clips.
struct IdleSpec {
  bool given = false;
  std::vector<std::filesystem::path> motion;  // BVH (or any asset) files, absolute
  std::vector<std::string> clips;             // clips of the character itself
  std::map<std::string, std::string> joint_map;  // data joint → character joint overrides
  std::uint64_t seed = 1;
  int components = 10;
  BalanceSpec balance;                        // `idle.balance:`
  int line = 0;
};

struct LookAtSpec {
  std::string base_clip;             // empty: the first clip, or the rest pose if none; "rest": the rest pose
  std::vector<std::string> chain;    // empty: DefaultLookAtChain()
  std::vector<double> limits_deg;    // empty: defaults
};

struct GestureSpec {
  ArmSide side = ArmSide::kRight;
  std::vector<std::string> chain;    // upper arm, forearm, hand; empty: DefaultArmChain()
  anim::ArmLimits limits;
};

// The character's gaze (anim/gaze.h): on by default; only a character with LeftEye and
// RightEye joints (the built-in figure) has eyes to turn.
struct GazeSpec {
  bool enabled = true;
  anim::GazeOptions options;
  int line = 0;
};

// One of the character's `lines:`: what it says (markup, parsed by the session with speech/),
// and the cue that starts it.
using speech::LineCue;
struct LineSpec {
  LineCue when = LineCue::kStart;
  std::string say;                  // the markup, as written
  double near = 1.5, far = 2.0;     // kNear: metres (far: the hysteresis that re-arms it)
  int line = 0;                     // where `say:` was written
};
// At most this many lines per character (each is synthesized at load and kept).
inline constexpr std::size_t kMaxLinesPerCharacter = 32;

struct CharacterSpec {
  std::string where;  // "scene.yaml:3", for messages
  std::string name;
  std::filesystem::path asset;  // absolute (resolved against the scene file)
  double scale = 1.0;
  Anchor anchor;
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  anim::ViewSphereOptions weights;
  anim::BlendMethod blend = anim::BlendMethod::kDlb;
  anim::DibOptions<double> dib;
  anim::PhaseMode phase = anim::PhaseMode::kShared;
  bool nlerp_sampling = false;  // `sampling: nlerp` (default slerp): see SamplingJob::nlerp
  bool has_lookat = false;
  LookAtSpec lookat;
  GestureSpec gesture;     // `gesture:`, for keys with `gesture: point|reach`
  std::vector<KeySpec> keys;
  anim::ScopeTable scopes;       // `scopes:` added to the built-in ones
  IdleSpec idle;           // `idle:`
  ScheduleSpec schedule;   // `schedule:`
  GazeSpec gaze;           // `gaze:`
  std::string voice = "slt";  // `voice:`, Flite's (the session checks it with speech/)
  int voice_line = 0;
  std::vector<LineSpec> lines;  // `lines:`

  // Where it stands, as the per-frame path takes it (anim/placement.h): anchor, scale, forward, up.
  anim::Placement placement() const;
};

struct Scene {
  std::filesystem::path file;
  std::vector<CharacterSpec> characters;
};

// Parses and checks a scene file (not the assets: AnimatedCharacter loads those).
Scene LoadScene(const std::filesystem::path& path);
Scene ParseScene(const std::string& text, const std::filesystem::path& file_for_messages);

// "x,y,z" (commas and/or spaces) → a unit viewpoint direction. Throws Error naming `what` when
// the text is not three finite numbers or the vector has zero length.
Eigen::Vector3d ParseViewpoint(const std::string& text, const std::string& what = "viewpoint");

// What a key plays, for the overlay and `arview view`: the clip's name, "lookat", "rest", or
// "<clip>@<seconds>".
std::string KeySourceLabel(const KeySpec& key);

}  // namespace arview::authoring
