#pragma once
// Authoring of key animations that look toward a viewpoint (the animator's work in the paper,
// automated): from a base clip, a chain of joints (body → spine → neck → head) turns so that the
// head's forward axis points along the key viewpoint, the rotation spread along the chain, each
// joint limited to its own angle.
//
// How the turn is spread: the yaw (about `up`) is shared evenly by the joints after the first,
// each within its limit, for viewpoints in front; toward the back their share tapers to zero and
// the first joint (by default the skeleton's root: the whole body) takes the rest. The yaw of
// every joint is then a continuous function of the viewpoint's azimuth all the way round, which
// is what lets keys all around the character blend without a seam behind it (a chain that turns
// left for 180° and right for 225° would blend to facing forward). The remaining tilt
// (elevation) is spread over the joints after the first, within their limits.
//
//   LookAtChain chain = MakeLookAtChain(character.skeleton, {}, {}, forward);   // defaults by name
//   Clip key = GenerateLookAtClip(character.skeleton, base_clip, chain, viewpoint);
//   Eigen::Vector3d f = HeadForward(chain, model_pose);   // for checks

#include "anim/character.h"
#include "anim/chains.h"
#include "anim/pose.h"

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace arview::authoring {

// Names of a body → spine → neck → head chain found by name in common rigs (Mixamo, CMU BVH,
// Fox, BCN_Epileptic, CesiumMan, Unreal/Unity humanoids): the head (or, without one, the deepest
// neck joint), its spine/neck/chest/back ancestors, and the skeleton's root first.
// Empty when no head- or neck-like joint exists.
std::vector<std::string> DefaultLookAtChain(const anim::Skeleton& skeleton);

// Builds the chain. Empty `names` uses DefaultLookAtChain(); empty `limits_deg` uses 180° for
// the first joint (the body), 45° per spine joint, 50° for the joint before the head and 70°
// for the head. The head's
// forward axis is the model-space `forward` at rest, expressed in the head's frame.
// Throws Error when a name is missing, the joints do not form one parent chain, or the
// counts differ.
anim::LookAtChain MakeLookAtChain(const anim::Skeleton& skeleton, const std::vector<std::string>& names,
                            const std::vector<double>& limits_deg, const Eigen::Vector3d& forward,
                            const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

// The base clip with the chain turned toward `viewpoint` (character frame) at every key time of
// the base clip (resampled at `sample_rate` Hz where the chain's parents move between keys).
// `base` may be nullptr: the result is a static look from the rest pose.
anim::Clip GenerateLookAtClip(const anim::Skeleton& skeleton, const anim::Clip* base, const anim::LookAtChain& chain,
                        const Eigen::Vector3d& viewpoint, double sample_rate = 30.0);

// The times a generated key samples: the base clip's duration at `sample_rate` Hz, both ends
// included (at least two samples); {0} for no base clip or a zero-length one.
std::vector<double> KeySampleTimes(const anim::Clip* base, double sample_rate);

// A generated key's clip before its chain is turned: a copy of `base` (or empty tracks for
// every joint of the rest pose), named after the base and `tag`, e.g. "Idle@lookat(0.00,0.00,1.00)";
// `target` is the key's unit viewpoint.
anim::Clip StartKeyClip(const anim::Skeleton& skeleton, const anim::Clip* base, std::string_view tag, const Eigen::Vector3d& target);

// The steps GenerateLookAtClip takes per sample, for keys built on top of it (gesture.h).
// `model` holds the model-space transforms of `pose` and is kept up to date.
// Rotates joint j by `delta` (model space) about the joint's own origin.
void RotateInModel(const anim::Skeleton& skeleton, int j, const Eigen::Quaterniond& delta, anim::LocalPose& pose,
                   std::vector<Eigen::Matrix4d>& model);
// Turns the chain toward `target` (unit, model space).
void ApplyLookAt(const anim::Skeleton& skeleton, const anim::LookAtChain& chain, const Eigen::Vector3d& target, anim::LocalPose& pose,
                 std::vector<Eigen::Matrix4d>& model);

}  // namespace arview::authoring
