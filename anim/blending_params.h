#pragma once
// Blending parameters of the MIRAnim engine (thesis §4.2.2, docs/method.md §2): how much of an
// action enters the blend, per joint and over time.
//
//   Curve fade = Curve::CosineFade(0.2, 0.2);        // in and out over 20% of the action each
//   double w = fade.Value(t, action_length);          // 0 → 1 → 0
//   JointMask torso = JointMask::Uniform(n, 0.0);     // nothing ...
//   torso.Set(ResolveScope(skeleton, "torso"), 1.0);  // ... but the upper body
//   BlendingParams p; p.curves = {fade}; p.masks = {torso};   // merged: product of all
//   double w_j = p.RotationWeight(j, t, length);      // per joint, per frame, no allocation
//
// A curve's lengths are fractions of the action's length (the thesis's "fadein 20" is 20%), or
// seconds when `in_seconds` is set (needed for unbounded actions such as the idle layer).

#include "anim/character.h"

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace arview::anim {

struct Curve {
  enum class Shape {
    kConstant,    // `peak` throughout
    kLinearFade,  // linear ramp up over fade_in, down over fade_out
    kCosineFade,  // the thesis's "goniofade": (1 − cos πx)/2 ramps, C¹ at the ends
    kAdsr,        // attack to `peak`, decay to `sustain`, hold, release to 0 (linear pieces)
    kCosineAdsr,  // the same with cosine pieces
  };
  Shape shape = Shape::kConstant;
  double fade_in = 0, fade_out = 0;            // fades
  double attack = 0, decay = 0, release = 0;   // ADSR
  double sustain = 1;                          // ADSR sustain level (times peak)
  double peak = 1;
  bool in_seconds = false;  // lengths in seconds rather than fractions of the action

  static Curve Constant(double value = 1) { Curve c; c.peak = value; return c; }
  static Curve LinearFade(double in, double out) { Curve c; c.shape = Shape::kLinearFade; c.fade_in = in; c.fade_out = out; return c; }
  static Curve CosineFade(double in, double out) { Curve c; c.shape = Shape::kCosineFade; c.fade_in = in; c.fade_out = out; return c; }
  static Curve Adsr(double a, double d, double s, double r, bool cosine = false) {
    Curve c;
    c.shape = cosine ? Shape::kCosineAdsr : Shape::kAdsr;
    c.attack = a; c.decay = d; c.sustain = s; c.release = r;
    return c;
  }

  // Value at local time t of an action of `length` seconds (infinity: unbounded, in which case
  // only in-seconds attack/fade-in pieces apply and nothing fades out). 0 outside [0, length].
  double Value(double t, double length) const;
  // Empty when the curve is usable with an action of `length`; otherwise why not.
  std::string Check(double length) const;
};

// Per-joint weights, for rotation and translation separately (a gesture may turn the arm but
// leave the root's translation to the layer below).
struct JointMask {
  std::vector<double> rotation;
  std::vector<double> translation;

  static JointMask Uniform(int joints, double weight) { return {std::vector<double>(joints, weight), std::vector<double>(joints, weight)}; }
  void Set(const std::vector<int>& joints, double weight) { SetRotation(joints, weight); SetTranslation(joints, weight); }
  void SetRotation(const std::vector<int>& joints, double weight);
  void SetTranslation(const std::vector<int>& joints, double weight);
  int size() const { return static_cast<int>(rotation.size()); }
};

// Named sets of joints. The built-in scopes are found by name in common rigs (Mixamo, CMU BVH,
// BCN_Epileptic, CesiumMan, Unreal/Unity humanoids) and include each found joint's descendants:
//   torso      the first spine/back/chest joint and everything above it (arms, neck, head)
//   legs       both legs (up-leg/thigh/hip joint of each side and below)
//   left_leg, right_leg, left_arm (clavicle/shoulder and below), right_arm
//   head       the first neck (or head) joint and below
//   root       the skeleton's root joint alone
//   all        every joint
// Scenes add their own (`scopes:`): a list of joint names, each with its descendants unless
// `descendants: false`.
struct ScopeSpec {
  std::vector<std::string> joints;
  bool descendants = true;
};
using ScopeTable = std::map<std::string, ScopeSpec>;

// Joint indices of scope `name` (custom scopes first, then the built-in ones). Throws Error when
// the scope is unknown or names a joint the skeleton lacks, or a built-in scope is not found.
std::vector<int> ResolveScope(const Skeleton& skeleton, const std::string& name, const ScopeTable& custom = {});
// The names of the built-in scopes.
const std::vector<std::string>& BuiltinScopes();
// The first joint of a side's arm (clavicle/collar, else shoulder, else upper arm) or leg
// (hip joint/up-leg/thigh, else leg/knee) found by name, or −1; also used by the humanoid map.
int ArmRoot(const Skeleton& skeleton, bool left);
int LegRoot(const Skeleton& skeleton, bool left);
// The first neck joint (else head), or −1.
int NeckJoint(const Skeleton& skeleton);
// Whether a joint name marks the left (+1), right (−1) or no (0) side.
int NameSide(const std::string& name);
// Descendants of `joint` including itself.
std::vector<int> Subtree(const Skeleton& skeleton, int joint);

// Any number of parameter objects merged (thesis: "multiplexed"): the weight of joint j at time
// t is gain · Π curves(t) · Π masks(j); the scaling Π scalings(t) exaggerates (>1) or damps (<1)
// the action's rotations relative to the rest pose.
struct BlendingParams {
  std::vector<Curve> curves;       // empty: weight 1
  std::vector<JointMask> masks;    // empty: every joint 1
  std::vector<Curve> scalings;     // empty: scale 1
  double gain = 1;

  double TimeWeight(double t, double length) const;
  double Scaling(double t, double length) const;
  // Mask products for joint j (1 without masks).
  double MaskRotation(int j) const;
  double MaskTranslation(int j) const;
};

}  // namespace arview::anim
