#pragma once
// Scene files (YAML) describing view-adaptive characters, and the runtime that animates one.
//
// For render/ and app/:
//
//   Scene scene = LoadScene("scene.yaml");               // throws anim::Error (file:line: why)
//   const CharacterSpec& spec = scene.characters[0];
//   AnimatedCharacter fox(spec);                          // loads the asset, builds key clips
//   const Character& c = fox.character();                 // meshes, materials, skeleton
//   Eigen::Matrix4d model_to_map = spec.ModelToMap();     // place it in the map
//   // every frame, with C the camera centre in map coordinates (C = −Rᵀt):
//   Eigen::Vector3d v = spec.ViewpointFromCamera(C);      // direction in the character's frame
//   const FrameOutput& out = fox.Update(v, time_seconds); // no allocation
//   out.skinning_matrices[j] (Matrix4f, model space) or out.skinning_dual_quats[j] → shader;
//   v_map = model_to_map · Σ w_i · skinning_matrices[joint_i] · v_mesh
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
//
// Flow mappings `{a: 1}` and flow sequences `[1, 2]` of scalars are accepted; see yaml.h.

#include "anim/character.h"
#include "anim_authoring/import.h"
#include "anim_authoring/gesture.h"
#include "anim_authoring/lookat.h"
#include "base/enum_table.h"
#include "base/geometry.h"
#include "anim/pose.h"
#include "anim/animator.h"
#include "anim/blending_params.h"
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

namespace arview::anim {

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
  std::vector<Curve> curves, scalings;
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
  ArmLimits limits;
};

struct CharacterSpec {
  std::string where;  // "scene.yaml:3", for messages
  std::string name;
  std::filesystem::path asset;  // absolute (resolved against the scene file)
  double scale = 1.0;
  Anchor anchor;
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  ViewSphereOptions weights;
  BlendMethod blend = BlendMethod::kDlb;
  DibOptions<double> dib;
  PhaseMode phase = PhaseMode::kShared;
  bool nlerp_sampling = false;  // `sampling: nlerp` (default slerp): see SamplingJob::nlerp
  bool has_lookat = false;
  LookAtSpec lookat;
  GestureSpec gesture;     // `gesture:`, for keys with `gesture: point|reach`
  std::vector<KeySpec> keys;
  ScopeTable scopes;       // `scopes:` added to the built-in ones
  IdleSpec idle;           // `idle:`
  ScheduleSpec schedule;   // `schedule:`

  // model space → map: translate(position) · rotation · uniform scale (anchor.scale · scale).
  Eigen::Matrix4d ModelToMap() const;
  // Unit direction from the character to a camera centre given in map coordinates, in the
  // character's frame; zero vector if the camera sits on the anchor.
  Eigen::Vector3d ViewpointFromCamera(const Eigen::Vector3d& camera_center_map) const;
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

struct FrameOutput {
  std::span<const double> weights;                  // one per key
  std::span<const Eigen::Matrix4d> model;           // joint model-space transforms
  std::span<const Eigen::Matrix4f> skinning_matrices;
  std::span<const DualQuatf> skinning_dual_quats;   // rigid part of skinning_matrices
  bool converged = true;                            // DIB converged on every joint
  int max_iterations = 0;                           // DIB, worst joint
};

// A scene's character: the asset loaded, its keys built (clips from the asset, generated
// look-at keys, static poses), and the runtime view-adaptive blend over them, with local-to-model
// and skinning after it.
class AnimatedCharacter {
 public:
  // Loads spec.asset and prepares one clip per key (from the asset, generated, or static).
  // Throws Error naming the scene/asset and the problem (e.g. a clip that does not exist).
  explicit AnimatedCharacter(const CharacterSpec& spec);
  AnimatedCharacter(std::shared_ptr<const Character> character, const CharacterSpec& spec);

  const Character& character() const { return *character_; }
  std::shared_ptr<const Character> shared_character() const { return character_; }
  std::shared_ptr<const Skeleton> shared_skeleton() const { return {character_, &character_->skeleton}; }
  const CharacterSpec& spec() const { return spec_; }
  const ViewSphere& view_sphere() const { return blend_->view_sphere(); }
  // One clip per key (shared between keys that name the same clip).
  const Clip& key_clip(int key) const { return *blend_->key(key).clip; }
  // The look-at chain used for generated keys (empty joints if none).
  const LookAtChain& lookat_chain() const { return chain_; }
  // The arm chain used for gesture keys (joints −1 if none).
  const ArmChain& arm_chain() const { return arm_; }
  // The runtime blend, to schedule it as an action (anim/schedule.h).
  std::shared_ptr<ViewAdaptiveBlend> view_adaptive() const { return blend_; }

  // Weights for `viewpoint` (character frame), then every key clip sampled at `time_seconds`,
  // blended, and converted to skinning transforms. Valid until the next call.
  const FrameOutput& Update(const Eigen::Vector3d& viewpoint, double time_seconds);

 private:
  std::vector<ViewAdaptiveKey> BuildKeys();

  std::shared_ptr<const Character> character_;
  CharacterSpec spec_;
  LookAtChain chain_;
  ArmChain arm_;
  std::shared_ptr<ViewAdaptiveBlend> blend_;
  // Per-frame buffers.
  LocalPose blended_;
  std::vector<Eigen::Matrix4d> model_;
  std::vector<Eigen::Matrix4f> skin_;
  std::vector<DualQuatf> skin_dq_;
  FrameOutput out_;
};

// What the appliance may override in the scene's schedule.
struct AnimatorOverrides {
  std::string idle_clip;                  // the default schedule's idle layer: this clip (looped)
  std::optional<double> hold_seconds, fade_seconds;  // tracking loss
};

// The character's animator (anim/animator.h): its scene `schedule:` built (objects, modifiers,
// curves, masks with scopes resolved on its skeleton, distance triggers and weights), or by
// default the idle underneath (the `idle:` synthesizer if given, else the look-at base clip
// looped, else the first clip, else the rest pose) and the view-adaptive action "view" on top.
// `character` must outlive the animator. Throws Error "scene:line: why". `notes` (if given)
// receive what the appliance should tell its user: a layer the scene asked for that the data
// cannot support (see BuildIdleLayer).
std::unique_ptr<Animator> BuildAnimator(const AnimatedCharacter& character, const AnimatorOverrides& overrides = {},
                                        std::vector<std::string>* notes = nullptr);

// The idle synthesizer of the character's `idle:` section (learned here), with what was learned.
std::shared_ptr<IdleSynthesizer> BuildIdle(const AnimatedCharacter& character, std::string* summary = nullptr);

// What BuildIdleLayer learned: the idle synthesizer's summary, the balance learner's (empty
// without `idle.balance:`), and notes for the user: "scene:line: idle.balance: <recording>: what
// it holds; 0 transitions: ..." when the balance layer was asked for and not built.
struct IdleLayerReport {
  std::string idle, balance;
  bool balance_built = false;  // the balance-shift layer runs under the synthesizer's variations
  std::vector<std::string> notes;
};

// The character's idle layer (`idle: true` objects and the default schedule's idle action): the
// idle synthesizer, under which, when the scene enables `idle.balance:` and its recording holds
// balance shifts, the balance-shift layer runs (anim/balance_shift.h: the synthesizer's
// variations on top of the shifts). A recording without a transition gives the synthesizer alone
// and a note: nothing is invented. Throws Error "scene:line: idle...: why" for bad data.
BlendablePtr BuildIdleLayer(const AnimatedCharacter& character, IdleLayerReport* report = nullptr);

}  // namespace arview::anim
