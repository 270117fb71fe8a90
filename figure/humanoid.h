#pragma once
// figure/: the project's own character, generated in code — a rigged, coloured humanoid with
// authored key animations — so that the demo and the tests have a lifelike character on a
// fresh machine with no downloads and no asset file in the repository.
//
//   figure::RegisterBuiltinCharacters();              // once, at program start
//   anim::Character c = authoring::LoadCharacter("builtin:figure");   // like any imported asset
//
// The figure ("builtin:figure"): 1.72 m tall, in metres, +Y up, facing +Z (its left is +X),
// standing on y = 0; the bind pose is the rest pose (arms 15° from the body).
// - Skeleton: 38 joints with Mixamo's names without the "mixamorig:" prefix (Hips, Spine,
//   Spine1, Spine2, Neck, Head, HeadTop_End, Left/RightShoulder, Arm, ForeArm, Hand,
//   HandIndex1, HandThumb1, Left/RightUpLeg, Leg, Foot, ToeBase, Toe_End), which CMU's BVH
//   names share (Hips, Spine, Spine1, Neck, Head, LeftArm, LeftForeArm, LeftUpLeg, ...), so
//   look-at chains, arm chains and humanoid masks find head, neck, spine, arms and legs by
//   name. Every rest rotation is the identity: joint frames are parallel to the model frame.
//   After the body's 29, the face's 9 under Head: Left/RightEye, Left/RightUpperLid,
//   Left/RightLowerLid, Left/RightBrow, Jaw; no clip moves them (gaze turns the eyes and lids,
//   anim/gaze.h).
// - Skin: smooth tubes along the limbs and the torso (elliptic cross-sections, rounded ends),
//   an ellipsoid head with eyes (white, iris, pupil) and their lids, brows, nose, lips over a
//   mouth and hair, mitten hands with thumbs, shoes; about 10 000 triangles in 26 meshes, each
//   with its material's colour (skin, shirt, trousers, shoes, hair, eyes, lips, eye white,
//   iris, mouth). Vertices near a joint blend the two bones on either
//   side of it (smoothstep over a band as wide as the limb), so bends stay smooth under
//   linear and dual-quaternion skinning.
// - Morph targets (figure/face_targets.h): 20 ARKit-named face shapes, then the 15 visemes
//   viseme_sil ... viseme_ou, on the face's small meshes (lips, mouth, brows, lids, head skin);
//   Ekman's six expressions are weights of the ARKit ones (ExpressionWeights).
// - Clips (30 keys per second): Idle (4 s loop: breathing, relaxed arms, small head motion),
//   WeightShift (6 s loop: the weight moves from leg to leg, the free knee bends, the feet
//   stay planted), Wave (3.2 s: the right arm rises, the hand waves three times, lowers),
//   Point (3 s: the right arm points straight ahead at shoulder height, holds, lowers),
//   Nod (2 s: a greeting nod). All start from, and the one-shots end in, Idle's posture, so
//   they blend and cross-fade without a jump.

#include <string>
#include <vector>

#include "anim/character.h"

namespace arview::figure {

// The humanoid above. Deterministic: the same character every call.
anim::Character MakeHumanoid();

// The figure walking, one cycle of two steps in place (the root stays put), looping: not one of
// the character's clips (a scene blends those, and all start in Idle's posture), but for figures
// moved along a path at kWalkSpeed, so that the feet keep pace with the ground on average
// (`arview synth room --walkers`).
inline constexpr double kWalkCycle = 1.1;   // seconds
inline constexpr double kStride = 0.6;      // metres each foot swings about the hips, front to back
inline constexpr double kWalkSpeed = kStride / (kWalkCycle / 2);  // m/s: the stance foot's mean speed back
anim::Clip MakeHumanoidWalk();

// Names accepted after "builtin:" (today: "figure").
std::vector<std::string> BuiltinCharacterNames();

// The built-in character `name` (without the "builtin:" prefix); throws anim::Error naming
// the asset and listing the known names when there is no such character.
anim::Character MakeBuiltinCharacter(const std::string& name);

// Makes authoring::LoadCharacter("builtin:<name>") return MakeBuiltinCharacter(name).
void RegisterBuiltinCharacters();

}  // namespace arview::figure
