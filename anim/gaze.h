#pragma once
// Gaze as people do it (issue 52): the eyes look at the viewer, look away in saccades with the
// statistics of Lee, Badler & Badler, "Eyes Alive" (SIGGRAPH 2002), the lids blink and follow
// the eyes. The viewer's eyes are the camera: mutual gaze means the character's eyes point at
// the camera centre. The numbers and where they come from: docs/anim.md, "Gaze".
//
// Two parts:
//   - GazeBehaviour: the seeded event process alone (saccades between mutual gaze and gaze
//     away, fixation lengths, blinks), as offsets from the viewer's direction. Deterministic in
//     (seed, t) like the idle synthesizer: sampling earlier than the last time restarts it
//     (a jump forward of more than an hour restarts it at the new time).
//   - Gaze: poses a skeleton's eye and lid joints each frame from it, after the look-at chain
//     has placed the head (the head-eye split: the eyes take the first ±35° sideways, 20° up and
//     25° down of the turn toward their target; the look-at chain took the rest, unchanged).
//
//   GazeRig rig = FindGazeRig(skeleton, forward, up);      // LeftEye/RightEye (+ lids) by name
//   Gaze gaze(skeleton, rig, options);                     // once
//   gaze.Apply(t, viewer_model, model, local);             // per frame, no allocation
//   gaze.frame().eyes_on_viewer, .blinking, .blinks_begun
//
// A character without eye joints has no rig (FindGazeRig's valid() is false): nothing is built
// for it and its frames are exactly what they were without gaze.

#include "anim/pose.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

namespace arview::anim {

enum class GazeMode { kListening, kTalking, kRest };

// Eyes Alive's statistics of one mode (docs/anim.md, "Gaze", says which numbers and why).
struct SaccadeStatistics {
  // Saccade directions in 8 bins of 45°: 0° = toward the viewer's right (the character's left),
  // counter-clockwise as the viewer sees the face (90° = up). Percentages, sum 100.
  std::array<double, 8> direction_percent{};
  double max_magnitude_deg = 0;  // the magnitude law A = −6.9·ln(P/15.7) is capped here
  double mutual_percent = 0;     // share of the time in mutual gaze
  // Fixation lengths (inter-saccadic intervals), Gaussian, seconds.
  double mutual_mean_s = 0, mutual_sd_s = 0, away_mean_s = 0, away_sd_s = 0;
};
const SaccadeStatistics& EyesAliveStatistics(GazeMode mode);
// Blinks per minute: 17 at rest, 26 in conversation (talking and listening).
double DefaultBlinkRate(GazeMode mode);

// The eyes' range about the head's forward axis, degrees.
struct EyeRange {
  double sideways_deg = 35, up_deg = 20, down_deg = 25;
};

struct GazeOptions {
  GazeMode mode = GazeMode::kListening;
  double blink_rate_per_min = 0;  // 0: DefaultBlinkRate(mode)
  EyeRange range;
  std::uint64_t seed = 1;
  // Throws Error naming the bad value.
  void Check() const;
};

// Saccade timing, from the paper: D = 25 ms + 2.4 ms per degree of amplitude.
inline double SaccadeDurationSeconds(double amplitude_deg) { return 0.025 + 0.0024 * amplitude_deg; }
// The lid's closure (0 open, 1 shut) `s` seconds after a blink began: shut at 50 ms, open again
// at 250 ms; 0 outside [0, 0.25].
double BlinkClosure(double s);
inline constexpr double kBlinkSeconds = 0.25;

// One saccade, as the behaviour drew it (for tests and statistics).
struct SaccadeEvent {
  double start = 0, duration = 0;  // seconds
  double amplitude_deg = 0;        // the angle between the gaze directions before and after
  double magnitude_deg = 0;        // the drawn magnitude of a look away (0 for a return)
  bool from_mutual = false, to_mutual = false;
};
struct BlinkEvent {
  double start = 0;
  bool with_saccade = false;  // pulled to a large gaze shift
};
// What a behaviour did, when asked to record it (GazeBehaviour::set_log; tests only).
struct GazeLog {
  std::vector<SaccadeEvent> saccades;
  std::vector<BlinkEvent> blinks;
  double mutual_seconds = 0;  // time spent fixating the viewer (not moving)
};

class GazeBehaviour {
 public:
  explicit GazeBehaviour(const GazeOptions& options);

  // Walks the events up to `t` (seconds, from 0). An earlier `t` restarts from the seed.
  void Advance(double t);
  // After Advance(t): the gaze offset from the viewer's direction, degrees (x: toward the
  // character's left, y: up); whether the eyes fixate the viewer; the lids' blink closure;
  // the blinks begun so far.
  Eigen::Vector2d offset_deg() const { return offset_; }
  bool mutual() const { return mutual_; }
  double blink_closure() const { return closure_; }
  bool blinking() const { return closure_ > 0; }
  long blinks_started() const { return blinks_started_; }
  double blink_rate_per_min() const { return blink_rate_; }

  // Switches the statistics (and, unless the options set a rate, the blink rate) to `mode` from
  // the next fixation and blink drawn on: talking switches a listening character to Eyes Alive's
  // talking statistics (issue 53). A restart keeps the mode last set.
  void SetMode(GazeMode mode);
  GazeMode mode() const { return mode_; }

  // Records every event from the next restart (or now) into `log` (tests; allocates).
  void set_log(GazeLog* log) { log_ = log; }

  // Large gaze shifts (drawn magnitude at least this, degrees) bring the next blink forward.
  static constexpr double kBlinkShiftDeg = 10;
  // Advance walks every event from the last time (or 0) on; a later time than this beyond it
  // restarts the walk there instead (the state is then that of the seed's start, moved there).
  static constexpr double kLongestWalkSeconds = 3600;

 private:
  void Restart(double origin);  // the seed's first fixation (on the viewer) begins at `origin`
  void NextFixation();  // at fixation_end_: the next target, a saccade to it, its fixation
  void BlinkAt(double t, bool with_saccade);
  void ScheduleNextBlink();
  double DrawFixation(bool mutual);
  Eigen::Vector2d DrawLookAway(double* magnitude_deg);

  GazeOptions options_;
  GazeMode mode_;
  const SaccadeStatistics* stats_;
  double blink_rate_ = 0;
  double p_mutual_ = 0;  // the chance that the next fixation is on the viewer
  std::mt19937_64 saccade_rng_, blink_rng_;
  double now_ = -1;
  // The current saccade (from_ → to_ over [saccade_start_, saccade_end_]) and the fixation after
  // it, to fixation_end_.
  Eigen::Vector2d from_ = Eigen::Vector2d::Zero(), to_ = Eigen::Vector2d::Zero();
  double saccade_start_ = 0, saccade_end_ = 0, fixation_end_ = 0;
  bool target_mutual_ = true;
  double next_blink_ = 0, last_blink_ = -1e9;
  long blinks_started_ = 0;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();
  bool mutual_ = true;
  double closure_ = 0;
  GazeLog* log_ = nullptr;
};

// The joints gaze turns, found by name: LeftEye/RightEye (required), LeftUpperLid,
// LeftLowerLid, RightUpperLid, RightLowerLid (optional), each eye's and lid's parent its head.
struct GazeRig {
  struct Side {
    int eye = -1, upper_lid = -1, lower_lid = -1;
  };
  std::array<Side, 2> eyes;  // left, right
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();  // the character's front and up, model space
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  bool valid() const { return eyes[0].eye >= 0 && eyes[1].eye >= 0; }
};
GazeRig FindGazeRig(const Skeleton& skeleton, const Eigen::Vector3d& forward = Eigen::Vector3d::UnitZ(),
                    const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

// What an animator needs to pose a character's eyes: its rig and the scene's options.
struct GazeSetup {
  GazeRig rig;
  GazeOptions options;
};

// What gaze did this frame, carried in AnimatorFrame.
struct GazeFrame {
  bool active = false;          // the character has eyes and gaze is on
  bool eyes_on_viewer = false;  // both eyes fixate the camera centre (mutual gaze, within range)
  bool blinking = false;        // a blink is under way
  int blinks_begun = 0;         // blinks that began since the previous frame (the blink events)
  float blink_closure = 0;      // the lids' closure, 0 open to 1 shut (a blink overrides the lid targets)
  bool talking_mode = false;    // Eyes Alive's talking statistics (the character is speaking)
};

class Gaze {
 public:
  // Throws Error when the rig is not valid for `skeleton` or the options are bad.
  Gaze(const Skeleton& skeleton, const GazeRig& rig, const GazeOptions& options);

  // Turns the eye joints of `local` toward the viewer (camera centre in model space; not finite:
  // unknown, the eyes look ahead) plus the behaviour's offset, within the eyes' range, and
  // places the lids. `model` holds the model-space matrices of `local`'s eye parents (the head
  // where the look-at chain put it); no other entry is read (the Animator computes only the chain
  // to them before this). No allocation.
  void Apply(double t, const Eigen::Vector3d& viewer_model, std::span<const Eigen::Matrix4d> model, LocalPose& local);

  // The eyes fixate the viewer (no look-away) from schedule time `from` until `until` (a line's
  // <gaze at="viewer"/>); the behaviour's draws go on underneath, so its seed's course is kept.
  void HoldOnViewer(double from, double until) {
    hold_on_viewer_from_ = from;
    hold_on_viewer_until_ = until;
  }
  // Eyes Alive's statistics of `mode` from the next draw on (GazeBehaviour::SetMode).
  void SetMode(GazeMode mode) { behaviour_.SetMode(mode); }

  // Apply on a pose whose model-space joints are not yet computed: first only the chain from the
  // root to the eyes' parents (head_chain(), into `model`), then Apply. The Animator and
  // PlacedCharacter run their one pass over every joint after it. `skeleton` is the one the
  // gaze was built for; throws Error when `local` or `model` does not fit it. No allocation.
  void PoseEyes(const Skeleton& skeleton, double t, const Eigen::Vector3d& viewer_model, LocalPose& local,
                std::span<Eigen::Matrix4d> model);
  // The eyes' parents and their ancestors, increasing (JointChain).
  std::span<const int> head_chain() const { return head_chain_; }

  const GazeFrame& frame() const { return frame_; }
  GazeBehaviour& behaviour() { return behaviour_; }
  const GazeRig& rig() const { return rig_; }

 private:
  struct Eye {
    int joint = -1, parent = -1, upper = -1, lower = -1;
    Eigen::Quaterniond rest, upper_rest, lower_rest;
    Eigen::Vector3d offset_parent;  // the eye's rest translation in its parent
    Eigen::Vector3d forward_parent, up_parent, side_parent;  // unit, the parent's frame at rest
  };
  // Yaw (toward side) and pitch (up) of `direction` (the parent's frame), degrees.
  static Eigen::Vector2d YawPitch(const Eye& e, const Eigen::Vector3d& direction);
  static Eigen::Quaterniond Turn(const Eye& e, double yaw_deg, double pitch_deg);

  GazeRig rig_;
  GazeOptions options_;
  GazeBehaviour behaviour_;
  std::array<Eye, 2> eyes_;
  std::vector<int> head_chain_;
  double last_time_ = -1;
  double hold_on_viewer_from_ = 0, hold_on_viewer_until_ = -1e300;
  GazeFrame frame_;
};

}  // namespace arview::anim
