#include "anim_authoring/gesture.h"

#include "anim/blending_params.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace arview::authoring {
namespace {

constexpr double kDeg = M_PI / 180;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool Has(const std::string& lower_name, std::initializer_list<const char*> words) {
  for (const char* w : words)
    if (lower_name.find(w) != std::string::npos) return true;
  return false;
}

bool IsFingerOrEnd(const std::string& n) {
  return Has(n, {"index", "thumb", "middle", "ring", "pinky", "finger", "end", "nub", "tip", "site"});
}

int SideSign(ArmSide side) { return side == ArmSide::kLeft ? 1 : -1; }  // as NameSide()

// The first joint (parents before children) of `side` whose lower-case name contains one of
// `words` and passes `accept`, or −1.
// NameSide(), plus CMU's lower-case one-letter prefixes ("rwrist", "lhumerus").
int ArmNameSide(const std::string& name) {
  if (const int s = anim::NameSide(name); s != 0) return s;
  const std::string n = Lower(name);
  if (n.size() > 1 && (n[0] == 'l' || n[0] == 'r'))
    for (const char* part : {"clavicle", "humerus", "radius", "wrist", "hand"})
      if (n.compare(1, std::string::npos, part) == 0) return n[0] == 'l' ? 1 : -1;
  return 0;
}

template <class Accept>
int FirstOnSide(const anim::Skeleton& sk, ArmSide side, std::initializer_list<const char*> words, Accept accept) {
  for (int j = 0; j < sk.size(); ++j) {
    const std::string n = Lower(sk.names[j]);
    if (Has(n, words) && ArmNameSide(sk.names[j]) == SideSign(side) && accept(n)) return j;
  }
  return -1;
}

int FirstChild(const anim::Skeleton& sk, int j) {
  for (int k = j + 1; k < sk.size(); ++k)
    if (sk.parents[k] == j) return k;
  return -1;
}

Eigen::Vector3d Position(std::span<const Eigen::Matrix4d> model, int j) { return model[j].block<3, 1>(0, 3); }

Eigen::Matrix3d RotationOf(const Eigen::Matrix4d& m) {
  Eigen::Matrix3d r = m.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) r.col(c).normalize();
  return r;
}

Eigen::Matrix3d ParentRotation(const anim::Skeleton& sk, int j, std::span<const Eigen::Matrix4d> model) {
  const int p = sk.parents[j];
  return RotationOf(p < 0 ? sk.root_parent : model[p]);
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDeg;
}

// Any unit vector perpendicular to v.
Eigen::Vector3d Perpendicular(const Eigen::Vector3d& v) {
  const Eigen::Vector3d other = std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(other).normalized();
}

std::vector<Eigen::Matrix4d> ModelPose(const anim::Skeleton& sk, const anim::LocalPose& pose) {
  std::vector<Eigen::Matrix4d> model(sk.size());
  anim::MustRun(anim::LocalToModelJob{&sk, &pose, model}, "gesture");
  return model;
}

}  // namespace

std::vector<std::string> DefaultArmChain(const anim::Skeleton& sk, ArmSide side) {
  auto not_finger = [](const std::string& n) { return !IsFingerOrEnd(n); };
  // The wrist before the hand: CMU's "rhand" hangs below "rwrist".
  int hand = FirstOnSide(sk, side, {"wrist"}, not_finger);
  if (hand < 0) hand = FirstOnSide(sk, side, {"hand"}, not_finger);
  if (hand >= 0) {
    const int fore = sk.parents[hand];
    const int upper = fore >= 0 ? sk.parents[fore] : -1;
    if (upper >= 0) return {sk.names[upper], sk.names[fore], sk.names[hand]};
    return {};
  }
  // Rigs without a hand joint (CesiumMan): the upper arm and the two joints below it.
  const int upper = FirstOnSide(sk, side, {"upperarm", "humerus", "arm"}, [](const std::string& n) {
    return !Has(n, {"forearm", "lowerarm"}) && !IsFingerOrEnd(n);
  });
  if (upper < 0) return {};
  const int fore = FirstChild(sk, upper);
  const int last = fore >= 0 ? FirstChild(sk, fore) : -1;
  if (last < 0) return {};
  return {sk.names[upper], sk.names[fore], sk.names[last]};
}

anim::ArmChain MakeArmChain(const anim::Skeleton& sk, const std::vector<std::string>& names_in, ArmSide side,
                      const anim::ArmLimits& limits, const Eigen::Vector3d& forward_in, const Eigen::Vector3d& up_in) {
  const std::string what = std::string("gesture: ") + ToString(side) + " arm";
  const std::vector<std::string> names = names_in.empty() ? DefaultArmChain(sk, side) : names_in;
  if (names.empty())
    throw anim::Error(what + ": no chain found by name (a wrist/hand joint with its forearm and upper arm, or an upper arm "
                       "with two joints below it); list the upper arm, forearm and hand in the scene's gesture.chain");
  if (names.size() != 3)
    throw anim::Error(what + ": gesture.chain needs 3 joints (upper arm, forearm, hand), not " + std::to_string(names.size()));
  int joints[3];
  for (int i = 0; i < 3; ++i) {
    joints[i] = sk.Find(names[i]);
    if (joints[i] < 0) throw anim::Error(what + ": the skeleton has no joint '" + names[i] + "'");
    if (i > 0 && sk.parents[joints[i]] != joints[i - 1])
      throw anim::Error(what + ": '" + names[i] + "' is not a child of '" + names[i - 1] + "'");
  }
  if (!(limits.elbow_min_deg >= 0 && limits.elbow_min_deg <= limits.elbow_max_deg && limits.elbow_max_deg <= 180))
    throw anim::Error(what + ": the elbow range must satisfy 0 <= min <= max <= 180 degrees");
  if (!(limits.shoulder_cone_deg > 0 && limits.shoulder_cone_deg <= 180))
    throw anim::Error(what + ": the shoulder cone must be in (0, 180] degrees");
  if (forward_in.norm() < 1e-9 || up_in.norm() < 1e-9) throw anim::Error(what + ": forward and up must not be zero");
  anim::ArmChain arm;
  arm.upper = joints[0];
  arm.fore = joints[1];
  arm.hand = joints[2];
  arm.limits = limits;
  const std::vector<Eigen::Matrix4d> rest = ModelPose(sk, anim::LocalPose::Rest(sk));
  const Eigen::Vector3d s = Position(rest, arm.upper), e = Position(rest, arm.fore), h = Position(rest, arm.hand);
  if ((e - s).norm() < 1e-9 || (h - e).norm() < 1e-9)
    throw anim::Error(what + ": '" + names[0] + "', '" + names[1] + "' and '" + names[2] + "' must not coincide at rest");
  const Eigen::Vector3d up = up_in.normalized();
  const Eigen::Vector3d forward = (forward_in - forward_in.dot(up) * up).normalized();
  // The arm's side from where the shoulder is (rigs disagree on which of ±x is "left").
  int root = arm.upper;
  while (sk.parents[root] >= 0) root = sk.parents[root];
  Eigen::Vector3d out = s - Position(rest, root);
  out -= out.dot(up) * up + out.dot(forward) * forward;
  if (out.norm() < 1e-9) out = SideSign(side) * up.cross(forward);
  out.normalize();
  const Eigen::Matrix3d parent = ParentRotation(sk, arm.upper, rest);
  arm.cone_axis_parent = parent.transpose() * (forward + out).normalized();
  arm.pole_parent = parent.transpose() * (-up + 0.5 * out - 0.25 * forward).normalized();
  return arm;
}

namespace {

struct ArmDirections {
  Eigen::Vector3d upper, fore;
};

// The arm's two directions aiming along `d` (see gesture.h); the elbow drops toward `pole`.
ArmDirections Aim(const Eigen::Vector3d& d, Gesture gesture, double l1, double l2, double bend,
                  const Eigen::Vector3d& pole, const Eigen::Vector3d& axis) {
  // The upper arm leaves the aimed line by `off` (point: the whole bend; reach: the shoulder's
  // angle in the arm's triangle, the hand at `reach` from the shoulder).
  const double reach = std::sqrt(l1 * l1 + l2 * l2 + 2 * l1 * l2 * std::cos(bend));
  const double off = gesture == Gesture::kPoint ? bend : std::atan2(l2 * std::sin(bend), l1 + l2 * std::cos(bend));
  Eigen::Vector3d b = pole - pole.dot(d) * d;
  if (b.norm() < 1e-6) b = -axis - (-axis).dot(d) * d;
  b = b.norm() > 1e-6 ? b.normalized() : Perpendicular(d);
  ArmDirections a;
  a.upper = std::cos(off) * d + std::sin(off) * b;
  a.fore = gesture == Gesture::kPoint ? d : (reach * d - l1 * a.upper).normalized();
  return a;
}

double Angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// One analytic solve of the arm toward `target` (see gesture.h).
void SolveArm(const anim::Skeleton& sk, const anim::ArmChain& arm, Gesture gesture, const Eigen::Vector3d& target, anim::LocalPose& pose,
              std::vector<Eigen::Matrix4d>& model) {
  const anim::ArmLimits& lim = arm.limits;
  const Eigen::Vector3d s = Position(model, arm.upper), e = Position(model, arm.fore), h = Position(model, arm.hand);
  const double l1 = (e - s).norm(), l2 = (h - e).norm();
  const Eigen::Matrix3d parent = ParentRotation(sk, arm.upper, model);
  const Eigen::Vector3d axis = (parent * arm.cone_axis_parent).normalized();
  const Eigen::Vector3d pole = (parent * arm.pole_parent).normalized();
  const double wanted = gesture == Gesture::kPoint ? lim.point_bend_deg : lim.reach_bend_deg;
  const double bend = std::clamp(wanted, lim.elbow_min_deg, lim.elbow_max_deg) * kDeg;
  const double cone = lim.shoulder_cone_deg * kDeg;
  const Eigen::Vector3d aimed = target.normalized();
  ArmDirections a = Aim(aimed, gesture, l1, l2, bend, pole, axis);
  if (Angle(a.upper, axis) > cone) {
    // Outside the shoulder's cone: the aimed line turns toward the cone's axis along the great
    // circle through both, just far enough (bisection) for the upper arm to be on the boundary.
    Eigen::Vector3d turn = aimed.cross(axis);
    turn = turn.norm() > 1e-9 ? turn.normalized() : Perpendicular(axis);  // exactly opposite: any side
    double lo = 0, hi = Angle(aimed, axis);
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo + hi);
      const ArmDirections m = Aim(Eigen::AngleAxisd(mid, turn) * aimed, gesture, l1, l2, bend, pole, axis);
      (Angle(m.upper, axis) > cone ? lo : hi) = mid;
    }
    a = Aim(Eigen::AngleAxisd(hi, turn) * aimed, gesture, l1, l2, bend, pole, axis);
  }
  RotateInModel(sk, arm.upper, Eigen::Quaterniond::FromTwoVectors(e - s, a.upper), pose, model);
  const Eigen::Vector3d e2 = Position(model, arm.fore), h2 = Position(model, arm.hand);
  RotateInModel(sk, arm.fore, Eigen::Quaterniond::FromTwoVectors(h2 - e2, a.fore), pose, model);
}

}  // namespace

void ApplyGesture(const anim::Skeleton& sk, const anim::ArmChain& arm, Gesture gesture, const Eigen::Vector3d& target,
                  anim::LocalPose& pose, std::vector<Eigen::Matrix4d>& model) {
  if (gesture == Gesture::kNone) return;
  SolveArm(sk, arm, gesture, target, pose, model);
}

anim::Clip GenerateGestureClip(const anim::Skeleton& sk, const anim::Clip* base, const anim::LookAtChain* lookat, const anim::ArmChain& arm,
                         Gesture gesture, const Eigen::Vector3d& viewpoint, double sample_rate) {
  if (viewpoint.norm() < 1e-9) throw anim::Error("gesture: the key viewpoint has zero length");
  if (arm.upper < 0 || arm.fore < 0 || arm.hand < 0) throw anim::Error("gesture: no arm chain");
  if (!(sample_rate > 0)) throw anim::Error("gesture: sample rate must be positive");
  const Eigen::Vector3d target = viewpoint.normalized();
  anim::Clip clip = StartKeyClip(sk, base, ToString(gesture), target);
  const std::vector<double> times = KeySampleTimes(base, sample_rate);
  std::vector<int> turned = lookat ? lookat->joints : std::vector<int>{};
  for (int j : {arm.upper, arm.fore})
    if (std::find(turned.begin(), turned.end(), j) == turned.end()) turned.push_back(j);
  for (int j : turned) clip.tracks[j].rotation.clear();
  anim::LocalPose pose(sk.size());
  for (double t : times) {
    if (base) anim::MustRun(anim::SamplingJob{&sk, base, t, false, &pose}, "gesture base clip");
    else pose = anim::LocalPose::Rest(sk);
    std::vector<Eigen::Matrix4d> model = ModelPose(sk, pose);
    if (lookat && !lookat->joints.empty()) ApplyLookAt(sk, *lookat, target, pose, model);
    ApplyGesture(sk, arm, gesture, target, pose, model);
    for (int j : turned) clip.tracks[j].rotation.push_back({t, pose.rigid[j].Rotation()});
  }
  return clip;
}

Eigen::Vector3d GestureDirection(const anim::ArmChain& arm, Gesture gesture, std::span<const Eigen::Matrix4d> model) {
  const int from = gesture == Gesture::kReach ? arm.upper : arm.fore;
  return (Position(model, arm.hand) - Position(model, from)).normalized();
}

double ElbowBendDeg(const anim::ArmChain& arm, std::span<const Eigen::Matrix4d> model) {
  return AngleDeg(Position(model, arm.fore) - Position(model, arm.upper),
                  Position(model, arm.hand) - Position(model, arm.fore));
}

double ShoulderConeAngleDeg(const anim::Skeleton& sk, const anim::ArmChain& arm, std::span<const Eigen::Matrix4d> model) {
  const Eigen::Vector3d axis = ParentRotation(sk, arm.upper, model) * arm.cone_axis_parent;
  return AngleDeg(Position(model, arm.fore) - Position(model, arm.upper), axis);
}

}  // namespace arview::authoring
