#pragma once
// The face while the character speaks (issue 53): a per-frame face track (how much speech owns
// the mouth, and the 15 viseme weights) laid over the frame the schedule made, with the mixing
// rules of VRM 1.0's expression overrides (docs/anim.md, "Speech on the face"):
//   - speech owns the mouth: the mouth's targets (viseme_*, jawOpen, mouth*, cheekPuff, tongue*)
//     take the track's visemes in proportion to `talking`; what the schedule's expression put on
//     them is scaled by 1 − talking (VRM's overrideMouth "block");
//   - the expression owns brows and eyes: the track never touches them;
//   - a blink overrides the lids: the lid targets (eyeBlink*, eyeSquint*, eyeWide*) are scaled by
//     1 − the blink's closure (VRM's overrideBlink, seen from the blink's side);
//   - the jaw: where the caller knows each viseme target's jaw share (the built-in figure's
//     table, figure/face_targets.h), the Jaw joint turns by Σ visemes·share times `jaw_open_deg`
//     and jawOpen takes −Σ visemes·share, so the visemes' own jaw share is replaced by the joint
//     (the lips keep their shapes; the two openings do not add up);
//   - a bilabial seals the lips: where PP outweighs every other viseme, mouthClose takes the whole
//     jaw opening (ARKit's mouthClose: the lips meet over an open jaw), less in proportion where
//     it does not, so that the neighbours' open jaw cannot hold the lips apart on a p, b or m.
// anim/ knows nothing of phones or text: the speech layer above (app/pipeline) samples its viseme
// curves into a FaceTrack every frame. The 15 viseme slots are in Meta's and OpenXR's order, the
// order of speech::Viseme.
//
//   FaceRig rig = FindFaceRig(skeleton, forward, up);     // by name, once
//   rig.jaw_share = figure's shares; rig.jaw_open_deg = 14;
//   ApplySpeechToFace(rig, track, pose);                  // after the schedule, before gaze
//   OverrideLidsWithBlink(rig, closure, pose);            // after gaze
// Nothing is allocated per frame.

#include "anim/pose.h"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

namespace arview::anim {

inline constexpr std::size_t kVisemeSlots = 15;
// viseme_sil viseme_PP ... viseme_ou: the morph target each slot drives.
const std::array<const char*, kVisemeSlots>& VisemeTargetNames();

// What speech does to the face this frame.
struct FaceTrack {
  float talking = 0;                          // 0..1: how much speech owns the mouth (ramps in and out)
  std::array<float, kVisemeSlots> visemes{};  // the slots' weights (sum 1 while talking)
};

// Who owns which morph target and joint, found once by name.
struct FaceRig {
  std::array<int, kVisemeSlots> viseme_targets;  // −1: the character lacks that viseme
  int jaw_open_target = -1;
  int mouth_close_target = -1;     // −1: the lips are not sealed over the jaw
  std::vector<int> mouth_targets;  // speech owns them while talking
  std::vector<int> lid_targets;    // a blink overrides them
  int jaw_joint = -1;
  Eigen::Vector3d jaw_axis_local = Eigen::Vector3d::UnitX();  // opening turns about it, the jaw's rest frame
  // Each viseme target's jaw opening as a share of jawOpen (0 where unknown: no joint turn).
  std::array<float, kVisemeSlots> jaw_share{};
  double jaw_open_deg = 0;  // the Jaw joint's turn for a share of 1 (jawOpen's angle)
  // The character has all 15 viseme targets: speech can move its mouth.
  bool valid() const;
  bool turns_jaw() const;  // a Jaw joint, jawOpen and some share known
};
FaceRig FindFaceRig(const Skeleton& skeleton, const Eigen::Vector3d& forward = Eigen::Vector3d::UnitZ(),
                    const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

// What the face did this frame, carried in AnimatorFrame.
struct FaceFrame {
  bool active = false;   // the character has a face rig that speech drives
  float talking = 0;     // the track's talking weight
  float jaw_open = 0;    // Σ visemes·jaw share · talking: the mouth's opening as a share of jawOpen
  int viseme = -1;       // the strongest viseme slot while talking, else −1
  float lip_seal = 0;    // how much mouthClose sealed the lips over the jaw (0..1)
};

// The speech rules above on `pose` (its morph weights and the Jaw joint's rotation); returns what
// it did. `pose` holds the schedule's blended frame.
FaceFrame ApplySpeechToFace(const FaceRig& rig, const FaceTrack& track, LocalPose& pose);
// The blink's override of the lid targets (closure 0 open .. 1 shut).
void OverrideLidsWithBlink(const FaceRig& rig, float closure, LocalPose& pose);

}  // namespace arview::anim
