#include "anim/lookat.h"

#include "anim/pose.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace arview::anim {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool Contains(const std::string& s, const char* part) { return s.find(part) != std::string::npos; }

bool IsEndMarker(const std::string& n) {
  return Contains(n, "end") || Contains(n, "top") || Contains(n, "nub") || Contains(n, "tip");
}

bool IsSpineLike(const std::string& n) {
  return Contains(n, "spine") || Contains(n, "chest") || Contains(n, "neck") || Contains(n, "torso") ||
         Contains(n, "back") || Contains(n, "head");
}

int Depth(const Skeleton& sk, int j) {
  int d = 0;
  for (; sk.parents[j] >= 0; j = sk.parents[j]) ++d;
  return d;
}

Eigen::Matrix3d RotationOf(const Eigen::Matrix4d& m) {
  Eigen::Matrix3d r = m.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) r.col(c).normalize();
  return r;
}

std::vector<Eigen::Matrix4d> ModelPose(const Skeleton& sk, const LocalPose& pose) {
  std::vector<Eigen::Matrix4d> model(sk.size());
  LocalToModelJob{&sk, &pose, model}.Run();
  return model;
}

// The rotation that turns `from` toward `to`: yaw about `up` first, then the remaining tilt, so
// that turning to look behind stays upright.
Eigen::Quaterniond TurnToward(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& up) {
  const Eigen::Vector3d fh = from - from.dot(up) * up, th = to - to.dot(up) * up;
  Eigen::Quaterniond yaw = Eigen::Quaterniond::Identity();
  if (fh.norm() > 1e-9 && th.norm() > 1e-9) {
    const double angle = std::atan2(fh.cross(th).dot(up), fh.dot(th));
    yaw = Eigen::AngleAxisd(angle, up);
  }
  const Eigen::Quaterniond tilt = Eigen::Quaterniond::FromTwoVectors(yaw * from, to);
  return tilt * yaw;
}

}  // namespace

std::vector<std::string> DefaultLookAtChain(const Skeleton& sk) {
  // The head: the shallowest joint named like a head (not an end marker); else the deepest
  // neck-like joint (rigs such as BCN_Epileptic and CesiumMan end their spine at the neck).
  int head = -1;
  for (int j = 0; j < sk.size(); ++j) {
    const std::string n = Lower(sk.names[j]);
    if (Contains(n, "head") && !IsEndMarker(n) && (head < 0 || Depth(sk, j) < Depth(sk, head))) head = j;
  }
  if (head < 0)
    for (int j = 0; j < sk.size(); ++j) {
      const std::string n = Lower(sk.names[j]);
      if (Contains(n, "neck") && !IsEndMarker(n) && (head < 0 || Depth(sk, j) > Depth(sk, head))) head = j;
    }
  if (head < 0) return {};
  std::vector<std::string> chain = {sk.names[head]};
  for (int p = sk.parents[head]; p >= 0 && sk.parents[p] >= 0; p = sk.parents[p]) {
    if (!IsSpineLike(Lower(sk.names[p]))) break;
    chain.push_back(sk.names[p]);
  }
  std::reverse(chain.begin(), chain.end());
  return chain;
}

LookAtChain MakeLookAtChain(const Skeleton& sk, const std::vector<std::string>& names_in,
                            const std::vector<double>& limits_deg, const Eigen::Vector3d& forward,
                            const Eigen::Vector3d& up) {
  const std::vector<std::string> names = names_in.empty() ? DefaultLookAtChain(sk) : names_in;
  if (names.empty()) throw Error("look-at: no head or neck joint found by name; list the chain joints");
  if (!limits_deg.empty() && limits_deg.size() != names.size())
    throw Error("look-at: " + std::to_string(limits_deg.size()) + " limits for " + std::to_string(names.size()) +
                " chain joints");
  if (forward.norm() < 1e-9 || up.norm() < 1e-9) throw Error("look-at: forward and up must not be zero");
  LookAtChain chain;
  chain.up = up.normalized();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int j = sk.Find(names[i]);
    if (j < 0) throw Error("look-at: the skeleton has no joint '" + names[i] + "'");
    if (i > 0) {
      bool descends = false;
      for (int p = sk.parents[j]; p >= 0; p = sk.parents[p]) descends = descends || p == chain.joints.back();
      if (!descends) throw Error("look-at: '" + names[i] + "' does not descend from '" + names[i - 1] + "'");
    }
    chain.joints.push_back(j);
    double limit;
    if (!limits_deg.empty()) limit = limits_deg[i];
    else if (i + 1 == names.size()) limit = 70;
    else if (i + 2 == names.size()) limit = 50;
    else limit = 45;
    if (!(limit > 0) || limit > 180) throw Error("look-at: limit for '" + names[i] + "' must be in (0, 180] degrees");
    chain.limits_rad.push_back(limit * M_PI / 180);
  }
  const std::vector<Eigen::Matrix4d> rest = ModelPose(sk, LocalPose::Rest(sk));
  chain.head_forward_local = (RotationOf(rest[chain.joints.back()]).transpose() * forward.normalized()).normalized();
  return chain;
}

Eigen::Vector3d HeadForward(const LookAtChain& chain, std::span<const Eigen::Matrix4d> model) {
  return RotationOf(model[chain.joints.back()]) * chain.head_forward_local;
}

namespace {

// Turns the chain of `pose` toward `target`; `model` is the pose's model-space transforms and
// is updated along with it.
void ApplyLookAt(const Skeleton& sk, const LookAtChain& chain, const Eigen::Vector3d& target, LocalPose& pose,
                 std::vector<Eigen::Matrix4d>& model) {
  const std::size_t n = chain.joints.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d f = HeadForward(chain, model);
    const Eigen::Quaterniond full = TurnToward(f, target, chain.up);
    const double angle = Eigen::AngleAxisd(full).angle();
    if (angle < 1e-12) break;
    const double share = std::min({1.0, 1.0 / double(n - i), chain.limits_rad[i] / angle});
    const Eigen::Quaterniond delta = Eigen::Quaterniond::Identity().slerp(share, full);
    const int j = chain.joints[i];
    const int p = sk.parents[j];
    const Eigen::Quaterniond parent(RotationOf(p < 0 ? sk.root_parent : model[p]));
    const Eigen::Quaterniond local = pose.rigid[j].Rotation();
    const Eigen::Vector3d t = pose.rigid[j].Translation();
    pose.rigid[j] = DualQuatd::FromRotationTranslation((parent.conjugate() * delta * parent * local).normalized(), t);
    // Refresh the model transforms below j (children come after their parents).
    for (int k = j; k < sk.size(); ++k) {
      if (k != j) {
        bool below = false;
        for (int a = sk.parents[k]; a >= j && !below; a = sk.parents[a]) below = a == j;
        if (!below) continue;
      }
      Eigen::Matrix4d local_m = pose.rigid[k].ToMatrix();
      local_m.block<3, 3>(0, 0) *= pose.scale[k].asDiagonal();
      const int pk = sk.parents[k];
      model[k] = (pk < 0 ? sk.root_parent : model[pk]) * local_m;
    }
  }
}

}  // namespace

Clip GenerateLookAtClip(const Skeleton& sk, const Clip* base, const LookAtChain& chain, const Eigen::Vector3d& viewpoint,
                        double sample_rate) {
  if (viewpoint.norm() < 1e-9) throw Error("look-at: the key viewpoint has zero length");
  if (chain.joints.empty()) throw Error("look-at: empty chain");
  if (!(sample_rate > 0)) throw Error("look-at: sample rate must be positive");
  const Eigen::Vector3d target = viewpoint.normalized();
  Clip clip;
  clip.tracks.resize(sk.size());
  std::vector<double> times = {0.0};
  if (base) {
    clip = *base;
    const int samples = std::max(2, static_cast<int>(std::ceil(base->duration * sample_rate)) + 1);
    times.clear();
    for (int s = 0; s < samples; ++s) times.push_back(base->duration * s / (samples - 1));
    if (base->duration <= 0) times = {0.0};
  }
  clip.name = (base ? base->name : std::string("rest")) + "@lookat";
  for (int j : chain.joints) clip.tracks[j].rotation.clear();
  LocalPose pose(sk.size());
  for (double t : times) {
    if (base) SamplingJob{&sk, base, t, false, &pose}.Run();
    else pose = LocalPose::Rest(sk);
    std::vector<Eigen::Matrix4d> model = ModelPose(sk, pose);
    ApplyLookAt(sk, chain, target, pose, model);
    for (int j : chain.joints) clip.tracks[j].rotation.push_back({t, pose.rigid[j].Rotation()});
  }
  return clip;
}

}  // namespace arview::anim
