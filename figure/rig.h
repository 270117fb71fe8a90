#pragma once
// The built-in figure's parts, shared by the files that make it (internal to figure/): the rig
// (skeleton and rest positions), and the helpers its skin and clips are written with.
//   rig.cpp: BuildRig; skin.cpp: the meshes and materials; clips.cpp: the authored clips.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "anim/character.h"

namespace arview::figure {

using Eigen::Quaterniond;
using Eigen::Vector3d;
using Eigen::Vector3f;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kKeysPerSecond = 30;
inline constexpr double kArmAbduction = 15;  // degrees between the arms and the body in the bind pose

inline double Rad(double degrees) { return degrees * kPi / 180; }
inline double SmoothStep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}
inline Quaterniond Axis(double degrees, const Vector3d& axis) { return Quaterniond(Eigen::AngleAxisd(Rad(degrees), axis.normalized())); }
inline Quaterniond Rx(double d) { return Axis(d, Vector3d::UnitX()); }
inline Quaterniond Ry(double d) { return Axis(d, Vector3d::UnitY()); }
inline Quaterniond Rz(double d) { return Axis(d, Vector3d::UnitZ()); }

// ---------------------------------------------------------------------------------------------
// The skeleton: rest rotations are the identity, so a joint's rest translation is the offset
// from its parent and its inverse bind matrix a translation by minus its model position.

struct Rig {
  anim::Skeleton skeleton;
  std::vector<Vector3d> position;  // model space, rest

  int Add(const std::string& name, const std::string& parent, const Vector3d& p) {
    const int parent_index = parent.empty() ? -1 : Index(parent);
    anim::Transform rest;
    rest.translation = parent_index < 0 ? p : Vector3d(p - position[parent_index]);
    Eigen::Matrix4d inverse_bind = Eigen::Matrix4d::Identity();
    inverse_bind.block<3, 1>(0, 3) = -p;
    skeleton.names.push_back(name);
    skeleton.parents.push_back(parent_index);
    skeleton.rest.push_back(rest);
    skeleton.inverse_bind.push_back(inverse_bind);
    position.push_back(p);
    return skeleton.size() - 1;
  }
  int Index(const std::string& name) const {
    const int j = skeleton.Find(name);
    if (j < 0) throw anim::Error("builtin:figure: internal error: no joint " + name);
    return j;
  }
  const Vector3d& At(const std::string& name) const { return position[Index(name)]; }
};

inline const char* SideName(int side) { return side > 0 ? "Left" : "Right"; }
inline std::string Sided(int side, const char* part) { return std::string(SideName(side)) + part; }

// Unit direction of the upper arm in the bind pose, for side +1 (left, +X) or −1.
inline Vector3d ArmDirection(int side) { return Vector3d(side * std::sin(Rad(kArmAbduction)), -std::cos(Rad(kArmAbduction)), 0); }

// The head's ellipsoid centre, the eyes' centres (x for the left eye, +X) and the jaw's pivot
// from it: the face's geometry and its joints share them.
inline Vector3d HeadCentre(const Rig& r) { return r.At("Head") + Vector3d(0, 0.085, 0.01); }
inline const Vector3d kEyeOffset(0.031, 0.010, 0.084);
inline const Vector3d kJawOffset(0, -0.030, 0.0);
inline constexpr double kEyeRadius = 0.012;

Rig BuildRig();
// The face's joints: per side Eye, UpperLid, LowerLid, Brow, then Jaw (all children of Head).
void AddFaceJoints(Rig& r);
// The figure's materials and skinned meshes, added to `character` (whose skeleton is the rig's).
void AddSkin(const Rig& rig, anim::Character& character);
// The face's morph targets (figure/face_targets.h) on the skin's face meshes; after AddSkin.
void AddFaceTargets(const Rig& rig, anim::Character& character);
// Idle, WeightShift, Wave, Point and Nod, sampled at kKeysPerSecond.
std::vector<anim::Clip> MakeClips(const Rig& rig);
// The walk cycle in place (humanoid.h, MakeHumanoidWalk), kWalkCycle seconds, looping.
anim::Clip MakeWalkClip(const Rig& rig);

}  // namespace arview::figure
