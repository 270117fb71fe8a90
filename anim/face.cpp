#include "anim/face.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

namespace arview::anim {

namespace {

bool StartsWith(const std::string& s, std::string_view prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// ARKit's and the visemes' mouth shapes: speech owns them while it talks.
bool IsMouthTarget(const std::string& name) {
  return StartsWith(name, "viseme_") || StartsWith(name, "jaw") || StartsWith(name, "mouth") || name == "cheekPuff" ||
         StartsWith(name, "tongue");
}

// The lids' shapes: a blink overrides them.
bool IsLidTarget(const std::string& name) {
  return StartsWith(name, "eyeBlink") || StartsWith(name, "eyeSquint") || StartsWith(name, "eyeWide");
}

// The joint's rest rotation in model space.
Eigen::Quaterniond RestModelRotation(const Skeleton& skeleton, int joint) {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (int j = joint; j >= 0; j = skeleton.parents[j]) q = skeleton.rest[j].rotation * q;
  const Eigen::Matrix3d root = skeleton.root_parent.block<3, 3>(0, 0);
  return Eigen::Quaterniond(root) * q;
}

}  // namespace

const std::array<const char*, kVisemeSlots>& VisemeTargetNames() {
  static const std::array<const char*, kVisemeSlots> names = {
      "viseme_sil", "viseme_PP", "viseme_FF", "viseme_TH", "viseme_DD", "viseme_kk", "viseme_CH", "viseme_SS",
      "viseme_nn",  "viseme_RR", "viseme_aa", "viseme_E",  "viseme_ih", "viseme_oh", "viseme_ou"};
  return names;
}

bool FaceRig::valid() const {
  return std::all_of(viseme_targets.begin(), viseme_targets.end(), [](int t) { return t >= 0; });
}

bool FaceRig::turns_jaw() const {
  return jaw_joint >= 0 && jaw_open_target >= 0 && jaw_open_deg > 0 &&
         std::any_of(jaw_share.begin(), jaw_share.end(), [](float s) { return s > 0; });
}

FaceRig FindFaceRig(const Skeleton& skeleton, const Eigen::Vector3d& forward, const Eigen::Vector3d& up) {
  FaceRig rig;
  for (std::size_t v = 0; v < kVisemeSlots; ++v) rig.viseme_targets[v] = skeleton.FindMorphTarget(VisemeTargetNames()[v]);
  rig.jaw_open_target = skeleton.FindMorphTarget("jawOpen");
  rig.mouth_close_target = skeleton.FindMorphTarget("mouthClose");
  for (int t = 0; t < skeleton.morph_target_count(); ++t) {
    if (IsMouthTarget(skeleton.morph_targets[t])) rig.mouth_targets.push_back(t);
    if (IsLidTarget(skeleton.morph_targets[t])) rig.lid_targets.push_back(t);
  }
  rig.jaw_joint = skeleton.Find("Jaw");
  if (rig.jaw_joint >= 0) {
    // The mouth opens by turning the chin down about the character's side axis (up × forward).
    const Eigen::Vector3d side = up.cross(forward).normalized();
    rig.jaw_axis_local = RestModelRotation(skeleton, rig.jaw_joint).conjugate() * side;
  }
  return rig;
}

FaceFrame ApplySpeechToFace(const FaceRig& rig, const FaceTrack& track, LocalPose& pose) {
  FaceFrame frame;
  frame.active = rig.valid() && !pose.morph.empty();
  if (!frame.active) return frame;
  const float talking = std::clamp(std::isfinite(track.talking) ? track.talking : 0.0f, 0.0f, 1.0f);
  frame.talking = talking;
  if (talking <= 0) return frame;
  for (int t : rig.mouth_targets) pose.morph[t] *= 1 - talking;
  float jaw = 0, strongest = -1;
  for (std::size_t v = 0; v < kVisemeSlots; ++v) {
    const float w = std::isfinite(track.visemes[v]) ? std::max(track.visemes[v], 0.0f) : 0.0f;
    pose.morph[rig.viseme_targets[v]] += talking * w;
    jaw += w * rig.jaw_share[v];
    if (w > strongest) {
      strongest = w;
      frame.viseme = static_cast<int>(v);
    }
  }
  jaw *= talking;
  frame.jaw_open = jaw;
  if (rig.mouth_close_target >= 0 && jaw > 0) {
    constexpr std::size_t kPP = 1;  // viseme_PP's slot
    float other = 0;
    for (std::size_t v = 0; v < kVisemeSlots; ++v)
      if (v != kPP) other = std::max(other, track.visemes[v]);
    const float pp = std::max(track.visemes[kPP], 0.0f);
    frame.lip_seal = other > 0 ? std::min(1.0f, pp / other) : (pp > 0 ? 1.0f : 0.0f);
    pose.morph[rig.mouth_close_target] += jaw * frame.lip_seal;
  }
  if (rig.turns_jaw() && jaw > 0) {
    // The visemes' own jaw share (their jawOpen part) is taken out and the joint turns instead.
    pose.morph[rig.jaw_open_target] -= jaw;
    const DualQuatd& current = pose.rigid[rig.jaw_joint];
    const Eigen::Quaterniond opened =
        current.Rotation() * Eigen::Quaterniond(Eigen::AngleAxisd(jaw * rig.jaw_open_deg * M_PI / 180, rig.jaw_axis_local));
    pose.rigid[rig.jaw_joint] = DualQuatd::FromRotationTranslation(opened.normalized(), current.Translation());
  }
  return frame;
}

void OverrideLidsWithBlink(const FaceRig& rig, float closure, LocalPose& pose) {
  if (pose.morph.empty() || !(closure > 0)) return;
  const float open = 1 - std::min(closure, 1.0f);
  for (int t : rig.lid_targets) pose.morph[t] *= open;
}

}  // namespace arview::anim
