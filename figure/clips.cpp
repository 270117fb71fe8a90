#include "figure/rig.h"

#include "figure/humanoid.h"

#include <functional>
#include <set>

namespace arview::figure {
namespace {

// ---------------------------------------------------------------------------------------------
// The clips. Each is a function of time that writes a pose (local rotations, the hips'
// translation), sampled at 30 keys per second.

class PoseWriter {
 public:
  explicit PoseWriter(const Rig& rig) : rig_(&rig), local_(rig.skeleton.size(), Quaterniond::Identity()) {}

  void Set(const std::string& joint, const Quaterniond& q) { local_[Touch(joint)] = q.normalized(); }
  void Turn(const std::string& joint, const Quaterniond& q) {
    const int j = Touch(joint);
    local_[j] = (local_[j] * q).normalized();
  }
  Quaterniond Local(const std::string& joint) const { return local_[rig_->Index(joint)]; }
  void MoveHips(const Vector3d& offset) {
    hips_offset_ = offset;
    hips_moved_ = true;
  }

  // Model-space rotation and position of a joint under the pose written so far.
  Quaterniond ModelRotation(int j) const {
    Quaterniond q = Quaterniond::Identity();
    for (int k = j; k >= 0; k = rig_->skeleton.parents[k]) q = local_[k] * q;
    return q;
  }
  Vector3d ModelPosition(int j) const {
    const int parent = rig_->skeleton.parents[j];
    Vector3d offset = rig_->skeleton.rest[j].translation;
    if (j == 0) offset += hips_offset_;
    if (parent < 0) return offset;
    return ModelPosition(parent) + ModelRotation(parent) * offset;
  }

  // The local rotation that points the bone `joint` → `child` along `model_direction`, with
  // the parent's pose as written so far (minimal rotation from the rest direction).
  Quaterniond AimRotation(const std::string& joint, const std::string& child, const Vector3d& model_direction) const {
    const int j = rig_->Index(joint);
    const Vector3d rest = rig_->skeleton.rest[rig_->Index(child)].translation.normalized();
    const int parent = rig_->skeleton.parents[j];
    const Quaterniond parent_model = parent < 0 ? Quaterniond::Identity() : ModelRotation(parent);
    return Quaterniond::FromTwoVectors(rest, parent_model.inverse() * model_direction.normalized());
  }
  // The local rotation that gives `joint` the model-space rotation `model`.
  Quaterniond LocalFor(const std::string& joint, const Quaterniond& model) const {
    const int parent = rig_->skeleton.parents[rig_->Index(joint)];
    return (parent < 0 ? Quaterniond::Identity() : ModelRotation(parent)).inverse() * model;
  }

  const std::vector<Quaterniond>& local() const { return local_; }
  const std::set<int>& touched() const { return touched_; }
  bool hips_moved() const { return hips_moved_; }
  const Vector3d& hips_offset() const { return hips_offset_; }

 private:
  int Touch(const std::string& joint) {
    const int j = rig_->Index(joint);
    touched_.insert(j);
    return j;
  }
  const Rig* rig_;
  std::vector<Quaterniond> local_;
  std::set<int> touched_;
  Vector3d hips_offset_ = Vector3d::Zero();
  bool hips_moved_ = false;
};

using PoseFunction = std::function<void(double t, PoseWriter& pose)>;

anim::Clip SampleClip(const Rig& rig, const std::string& name, double duration, const PoseFunction& f) {
  anim::Clip clip;
  clip.name = name;
  clip.duration = duration;
  clip.ticks_per_second = kKeysPerSecond;
  clip.tracks.resize(rig.skeleton.size());
  const int keys = static_cast<int>(std::lround(duration * kKeysPerSecond));
  for (int i = 0; i <= keys; ++i) {
    const double t = duration * i / keys;
    PoseWriter pose(rig);
    f(t, pose);
    for (int j : pose.touched()) {
      Quaterniond q = pose.local()[j];
      // Keep consecutive keys in one hemisphere, so interpolation takes the short way.
      if (!clip.tracks[j].rotation.empty() && clip.tracks[j].rotation.back().value.dot(q) < 0) q.coeffs() *= -1;
      clip.tracks[j].rotation.push_back({t, q});
    }
    if (pose.hips_moved()) clip.tracks[0].translation.push_back({t, rig.skeleton.rest[0].translation + pose.hips_offset()});
  }
  return clip;
}

// Rotation that bends a bone whose rest direction is `bone` forward (toward +Z) by `degrees`.
Quaterniond Flex(const Vector3d& bone, double degrees) { return Axis(degrees, bone.cross(Vector3d::UnitZ())); }

// The posture every clip starts from: arms relaxed closer to the body, elbows a little bent,
// breathing with phase `breath` (radians).
void Relaxed(PoseWriter& p, double breath) {
  const double b = std::sin(breath);
  p.Set("Spine1", Rx(-1.2 * b));
  p.Set("Spine2", Rx(-0.8 * b));
  p.Set("Neck", Rx(0.9 * b));
  p.Set("Head", Rx(0.6 * b));
  for (int side : {1, -1}) {
    const Vector3d d = ArmDirection(side);
    p.Set(Sided(side, "Shoulder"), Rz(side * 1.0 * (0.5 + 0.5 * b)));
    p.Set(Sided(side, "Arm"), Rx(-4 - 0.8 * b) * Rz(-side * 9.0));
    p.Set(Sided(side, "ForeArm"), Flex(d, 14 + 1.5 * b));
    p.Set(Sided(side, "Hand"), Flex(d, 6));
    p.Set(Sided(side, "UpLeg"), Quaterniond::Identity());
    p.Set(Sided(side, "Leg"), Quaterniond::Identity());
    p.Set(Sided(side, "Foot"), Quaterniond::Identity());
  }
  p.Set("Hips", Quaterniond::Identity());
  p.Set("Spine", Quaterniond::Identity());
  p.MoveHips(Vector3d::Zero());
}

double Period(double t, double period) { return 2 * kPi * t / period; }

// Raise-hold-lower envelope of a one-shot gesture.
double Envelope(double t, double rise, double fall_start, double end) {
  if (t < rise) return SmoothStep(t / rise);
  if (t > fall_start) return SmoothStep((end - t) / (end - fall_start));
  return 1;
}

void Idle(double t, PoseWriter& p) {
  Relaxed(p, Period(t, 4));
  p.Turn("Hips", Rz(0.6 * std::sin(Period(t, 4) + 0.7)));
  p.Turn("Spine", Rz(-0.5 * std::sin(Period(t, 4) + 0.7)));
  p.Turn("Neck", Ry(2.0 * std::sin(Period(t, 4) + 1.9)));
  p.Turn("Head", Ry(1.5 * std::sin(Period(t, 4) + 2.4)) * Rx(1.2 * std::sin(Period(t, 2) + 0.3)));
}

// Two-bone leg placed so that the ankle reaches `ankle_target` with the knee forward, the
// foot at model rotation `foot_model`.
void PlaceLeg(const Rig& r, PoseWriter& p, int side, const Vector3d& ankle_target, const Quaterniond& foot_model) {
  const std::string up = Sided(side, "UpLeg"), leg = Sided(side, "Leg"), foot = Sided(side, "Foot");
  const Vector3d hip = p.ModelPosition(r.Index(up));
  const double l1 = (r.At(leg) - r.At(up)).norm(), l2 = (r.At(foot) - r.At(leg)).norm();
  const Vector3d to_ankle = ankle_target - hip;
  const double reach = std::min(to_ankle.norm(), 0.999 * (l1 + l2));
  const Vector3d axis = to_ankle.normalized();
  const double hip_angle = std::acos(std::clamp((l1 * l1 + reach * reach - l2 * l2) / (2 * l1 * reach), -1.0, 1.0));
  const Vector3d pole = (Vector3d::UnitZ() - Vector3d::UnitZ().dot(axis) * axis).normalized();
  const Vector3d thigh = std::cos(hip_angle) * axis + std::sin(hip_angle) * pole;
  p.Set(up, p.AimRotation(up, leg, thigh));
  const Vector3d knee = hip + l1 * thigh;
  p.Set(leg, p.AimRotation(leg, foot, hip + reach * axis - knee));
  p.Set(foot, p.LocalFor(foot, foot_model));
}

void WeightShift(const Rig& r, double t, PoseWriter& p) {
  Relaxed(p, Period(t, 3));
  const double s = std::sin(Period(t, 6));  // + : weight on the left leg
  const double roll = 2.5 * s;
  p.MoveHips({0.035 * s, -0.008 * std::abs(s), 0});
  p.Set("Hips", Rz(roll));
  p.Set("Spine", Rz(-0.6 * roll));
  p.Turn("Spine2", Rz(-0.3 * roll));
  p.Turn("Neck", Rz(-0.1 * roll));
  for (int side : {1, -1}) {
    const double free = std::max(0.0, -side * s);  // how much this leg is off its weight
    const Vector3d ankle = r.At(Sided(side, "Foot")) + Vector3d(0, 0.025 * free, -0.012 * free);
    PlaceLeg(r, p, side, ankle, Rx(8 * free));
  }
}

// The right arm's pose for a raised-arm gesture, mixed with the pose written so far by
// `weight`: upper arm and forearm directions in model space, the forearm twisted about itself
// (of the two quarter twists, the one that turns the palm — the hand's +X side, which faces the
// body at rest — most toward `palm_toward`).
void RaiseRightArm(const Rig& r, PoseWriter& p, double weight, const Vector3d& upper, const Vector3d& fore,
                   const Vector3d& palm_toward, double hand_flex) {
  const std::string arm = "RightArm", forearm = "RightForeArm", hand = "RightHand";
  const Quaterniond arm_relaxed = p.Local(arm), fore_relaxed = p.Local(forearm), hand_relaxed = p.Local(hand);
  const Vector3d bone = ArmDirection(-1);
  p.Set(arm, p.AimRotation(arm, forearm, upper));
  const Quaterniond arm_raised = p.Local(arm);
  const Quaterniond fore_aimed = p.AimRotation(forearm, hand, fore);
  p.Set(hand, Flex(bone, hand_flex));
  double best = -2;
  Quaterniond fore_raised = fore_aimed;
  for (double twist : {-90.0, 0.0, 90.0}) {
    const Quaterniond candidate = fore_aimed * Axis(twist, bone);
    p.Set(forearm, candidate);
    const double facing = (p.ModelRotation(r.Index(hand)) * Vector3d::UnitX()).dot(palm_toward.normalized());
    if (facing > best) {
      best = facing;
      fore_raised = candidate;
    }
  }
  p.Set(arm, arm_relaxed.slerp(weight, arm_raised));
  p.Set(forearm, fore_relaxed.slerp(weight, fore_raised));
  p.Set(hand, hand_relaxed.slerp(weight, Flex(bone, hand_flex)));
}

void Wave(const Rig& r, double t, PoseWriter& p) {
  Relaxed(p, Period(t, 3.2));
  const double e = Envelope(t, 0.6, 2.6, 3.2);
  const double swing = std::sin(Period(std::max(0.0, t - 0.6), 2.0 / 3.0));  // three waves in 2 s
  p.Turn("Spine2", Rz(3.0 * e));
  p.Turn("Head", Rz(-2.5 * e) * Ry(-4 * e));
  RaiseRightArm(r, p, e, {-0.72, 0.38, 0.35}, {-0.12 - 0.38 * swing, 1.0, 0.22}, {0, 0, 1}, -10);
}

void Point(const Rig& r, double t, PoseWriter& p) {
  Relaxed(p, Period(t, 3));
  const double e = Envelope(t, 0.5, 2.3, 3.0);
  p.Turn("Spine1", Ry(-5 * e));
  p.Turn("Head", Ry(-4 * e));
  RaiseRightArm(r, p, e, {-0.10, 0.06, 1.0}, {-0.05, 0.04, 1.0}, {1, -1, 0}, 0);
}

// The walk cycle in place (the root stays put; whoever plays it moves the figure along its path
// at kWalkSpeed): the feet swing ±kStride / 2 about the hips in antiphase, the swinging foot
// lifted, the hips a little lower and bobbing twice a cycle, the arms swinging against the legs.
// The stance foot slides back at the same speed only on average (a sinusoid, not a plant).
void Walk(const Rig& r, double t, PoseWriter& p) {
  Relaxed(p, Period(t, kWalkCycle));
  const double phase = Period(t, kWalkCycle);
  p.MoveHips({0, -0.045 + 0.012 * std::cos(2 * phase), 0});
  p.Set("Hips", Ry(4 * std::sin(phase)));
  p.Set("Spine", Ry(-5 * std::sin(phase)));
  for (int side : {1, -1}) {
    const double own = phase + (side > 0 ? 0 : kPi);
    const double forward = 0.5 * kStride * std::sin(own);
    const double lift = 0.07 * std::max(0.0, std::cos(own));  // while the foot swings forward
    const Vector3d ankle = r.At(Sided(side, "Foot")) + Vector3d(0, lift, forward);
    PlaceLeg(r, p, side, ankle, Rx(-12 * std::sin(own)));
    p.Turn(Sided(side, "Arm"), Rx(22 * std::sin(own)));  // + turns the arm back: against its leg
    p.Turn(Sided(side, "ForeArm"), Flex(ArmDirection(side), 8 + 8 * std::max(0.0, -std::sin(own))));
  }
}

void Nod(double t, PoseWriter& p) {
  Relaxed(p, Period(t, 2));
  const double nod = std::pow(std::sin(kPi * std::clamp(t / 1.4, 0.0, 1.0)), 2);
  p.Turn("Neck", Rx(6 * nod));
  p.Turn("Head", Rx(13 * nod));
  p.Turn("Spine2", Rx(2 * nod));
}

}  // namespace

std::vector<anim::Clip> MakeClips(const Rig& rig) {
  std::vector<anim::Clip> clips;
  clips.push_back(SampleClip(rig, "Idle", 4.0, Idle));
  clips.push_back(SampleClip(rig, "WeightShift", 6.0, [&](double t, PoseWriter& p) { WeightShift(rig, t, p); }));
  clips.push_back(SampleClip(rig, "Wave", 3.2, [&](double t, PoseWriter& p) { Wave(rig, t, p); }));
  clips.push_back(SampleClip(rig, "Point", 3.0, [&](double t, PoseWriter& p) { Point(rig, t, p); }));
  clips.push_back(SampleClip(rig, "Nod", 2.0, Nod));
  return clips;
}

anim::Clip MakeWalkClip(const Rig& rig) {
  return SampleClip(rig, "Walk", kWalkCycle, [&](double t, PoseWriter& p) { Walk(rig, t, p); });
}

}  // namespace arview::figure
