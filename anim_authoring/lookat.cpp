#include "anim_authoring/lookat.h"

#include "anim/pose.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace arview::authoring {
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

int Depth(const anim::Skeleton& sk, int j) {
  int d = 0;
  for (; sk.parents[j] >= 0; j = sk.parents[j]) ++d;
  return d;
}

Eigen::Matrix3d RotationOf(const Eigen::Matrix4d& m) {
  Eigen::Matrix3d r = m.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) r.col(c).normalize();
  return r;
}

std::vector<Eigen::Matrix4d> ModelPose(const anim::Skeleton& sk, const anim::LocalPose& pose) {
  std::vector<Eigen::Matrix4d> model(sk.size());
  anim::MustRun(anim::LocalToModelJob{&sk, &pose, model}, "look-at");
  return model;
}

}  // namespace

std::vector<std::string> DefaultLookAtChain(const anim::Skeleton& sk) {
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
  int top = head;
  for (int p = sk.parents[head]; p >= 0 && sk.parents[p] >= 0; p = sk.parents[p]) {
    if (!IsSpineLike(Lower(sk.names[p]))) break;
    chain.push_back(sk.names[p]);
    top = p;
  }
  // The body: the skeleton's root above the spine turns the whole character.
  int root = top;
  while (sk.parents[root] >= 0) root = sk.parents[root];
  if (root != top) chain.push_back(sk.names[root]);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

anim::LookAtChain MakeLookAtChain(const anim::Skeleton& sk, const std::vector<std::string>& names_in,
                            const std::vector<double>& limits_deg, const Eigen::Vector3d& forward,
                            const Eigen::Vector3d& up) {
  const std::vector<std::string> names = names_in.empty() ? DefaultLookAtChain(sk) : names_in;
  if (names.empty()) throw anim::Error("look-at: no head or neck joint found by name; list the chain joints");
  if (!limits_deg.empty() && limits_deg.size() != names.size())
    throw anim::Error("look-at: " + std::to_string(limits_deg.size()) + " limits for " + std::to_string(names.size()) +
                " chain joints");
  if (forward.norm() < 1e-9 || up.norm() < 1e-9) throw anim::Error("look-at: forward and up must not be zero");
  anim::LookAtChain chain;
  chain.up = up.normalized();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int j = sk.Find(names[i]);
    if (j < 0) throw anim::Error("look-at: the skeleton has no joint '" + names[i] + "'");
    if (i > 0) {
      bool descends = false;
      for (int p = sk.parents[j]; p >= 0; p = sk.parents[p]) descends = descends || p == chain.joints.back();
      if (!descends) throw anim::Error("look-at: '" + names[i] + "' does not descend from '" + names[i - 1] + "'");
    }
    chain.joints.push_back(j);
    double limit;
    if (!limits_deg.empty()) limit = limits_deg[i];
    else if (i == 0 && names.size() > 1) limit = 180;  // the body: takes what the others leave
    else if (i + 1 == names.size()) limit = 70;
    else if (i + 2 == names.size()) limit = 50;
    else limit = 45;
    if (!(limit > 0) || limit > 180) throw anim::Error("look-at: limit for '" + names[i] + "' must be in (0, 180] degrees");
    chain.limits_rad.push_back(limit * M_PI / 180);
  }
  const std::vector<Eigen::Matrix4d> rest = ModelPose(sk, anim::LocalPose::Rest(sk));
  chain.head_forward_local = (RotationOf(rest[chain.joints.back()]).transpose() * forward.normalized()).normalized();
  return chain;
}

namespace {

// Refreshes the model transforms of joint j and everything below it (children follow parents).
void RefreshBelow(const anim::Skeleton& sk, int j, const anim::LocalPose& pose, std::vector<Eigen::Matrix4d>& model) {
  for (int k = j; k < sk.size(); ++k) {
    if (k != j) {
      bool below = false;
      for (int a = sk.parents[k]; a >= j && !below; a = sk.parents[a]) below = a == j;
      if (!below) continue;
    }
    Eigen::Matrix4d local = pose.rigid[k].ToMatrix();
    local.block<3, 3>(0, 0) *= pose.scale[k].asDiagonal();
    const int p = sk.parents[k];
    model[k] = (p < 0 ? sk.root_parent : model[p]) * local;
  }
}

}  // namespace

void RotateInModel(const anim::Skeleton& sk, int j, const Eigen::Quaterniond& delta, anim::LocalPose& pose,
                   std::vector<Eigen::Matrix4d>& model) {
  const int p = sk.parents[j];
  const Eigen::Quaterniond parent(RotationOf(p < 0 ? sk.root_parent : model[p]));
  const Eigen::Quaterniond local = pose.rigid[j].Rotation();
  const Eigen::Vector3d t = pose.rigid[j].Translation();
  pose.rigid[j] = anim::DualQuatd::FromRotationTranslation((parent.conjugate() * delta * parent * local).normalized(), t);
  RefreshBelow(sk, j, pose, model);
}

namespace {

// The yaw an upper joint takes for a total yaw `phi` (radians, in (−π, π]): an even share up to
// its limit for viewpoints in front, tapering back to zero toward the back. Periodic and
// continuous in phi, so that keys all around the circle blend without a seam; the first chain
// joint takes the rest (it alone winds once around as phi goes round).
double UpperYaw(double phi, double share, double limit) {
  const double a = std::abs(phi);
  const double front = std::min(std::min(a, M_PI / 2) * share, limit);
  const double y = a <= M_PI / 2 ? front : front * (M_PI - a) / (M_PI / 2);
  return phi < 0 ? -y : y;
}

}  // namespace

void ApplyLookAt(const anim::Skeleton& sk, const anim::LookAtChain& chain, const Eigen::Vector3d& target, anim::LocalPose& pose,
                 std::vector<Eigen::Matrix4d>& model) {
  const std::size_t n = chain.joints.size();
  const Eigen::Vector3d& up = chain.up;
  // Yaw about the up axis, measured on the horizontal projections.
  const Eigen::Vector3d f = anim::HeadForward(chain, model);
  const Eigen::Vector3d fh = f - f.dot(up) * up, th = target - target.dot(up) * up;
  if (fh.norm() > 1e-9 && th.norm() > 1e-9) {
    const double phi = std::atan2(fh.cross(th).dot(up), fh.dot(th));
    double upper_total = 0;
    for (std::size_t i = 1; i < n; ++i) {
      const double y = UpperYaw(phi, 1.0 / double(n), chain.limits_rad[i]);
      upper_total += y;
      RotateInModel(sk, chain.joints[i], Eigen::Quaterniond(Eigen::AngleAxisd(y, up)), pose, model);
    }
    const double first = phi - upper_total;
    RotateInModel(sk, chain.joints[0], Eigen::Quaterniond(Eigen::AngleAxisd(first, up)), pose, model);
  }
  // The remaining tilt (elevation), spread over the upper joints within their limits.
  const std::size_t first_tilt = n > 1 ? 1 : 0;
  for (std::size_t i = first_tilt; i < n; ++i) {
    const Eigen::Quaterniond full = Eigen::Quaterniond::FromTwoVectors(anim::HeadForward(chain, model), target);
    const double angle = Eigen::AngleAxisd(full).angle();
    if (angle < 1e-12) break;
    const double share = std::min({1.0, 1.0 / double(n - i), chain.limits_rad[i] / angle});
    RotateInModel(sk, chain.joints[i], Eigen::Quaterniond::Identity().slerp(share, full), pose, model);
  }
}

std::vector<double> KeySampleTimes(const anim::Clip* base, double sample_rate) {
  if (!base || base->duration <= 0) return {0.0};
  const int samples = std::max(2, static_cast<int>(std::ceil(base->duration * sample_rate)) + 1);
  std::vector<double> times;
  for (int s = 0; s < samples; ++s) times.push_back(base->duration * s / (samples - 1));
  return times;
}

anim::Clip StartKeyClip(const anim::Skeleton& sk, const anim::Clip* base, std::string_view tag, const Eigen::Vector3d& target) {
  anim::Clip clip;
  clip.tracks.resize(sk.size());
  if (base) clip = *base;
  char where[96];
  std::snprintf(where, sizeof(where), "@%.*s(%.2f,%.2f,%.2f)", static_cast<int>(tag.size()), tag.data(), target.x(),
                target.y(), target.z());
  clip.name = (base ? base->name : std::string("rest")) + where;
  return clip;
}

anim::Clip GenerateLookAtClip(const anim::Skeleton& sk, const anim::Clip* base, const anim::LookAtChain& chain, const Eigen::Vector3d& viewpoint,
                        double sample_rate) {
  if (viewpoint.norm() < 1e-9) throw anim::Error("look-at: the key viewpoint has zero length");
  if (chain.joints.empty()) throw anim::Error("look-at: empty chain");
  if (!(sample_rate > 0)) throw anim::Error("look-at: sample rate must be positive");
  const Eigen::Vector3d target = viewpoint.normalized();
  anim::Clip clip = StartKeyClip(sk, base, "lookat", target);
  const std::vector<double> times = KeySampleTimes(base, sample_rate);
  for (int j : chain.joints) clip.tracks[j].rotation.clear();
  anim::LocalPose pose(sk.size());
  for (double t : times) {
    if (base) anim::MustRun(anim::SamplingJob{&sk, base, t, false, &pose}, "look-at base clip");
    else pose = anim::LocalPose::Rest(sk);
    std::vector<Eigen::Matrix4d> model = ModelPose(sk, pose);
    ApplyLookAt(sk, chain, target, pose, model);
    for (int j : chain.joints) clip.tracks[j].rotation.push_back({t, pose.rigid[j].Rotation()});
  }
  return clip;
}

}  // namespace arview::authoring
