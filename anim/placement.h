#pragma once
// Where a character stands in the map, and the maths every per-frame user of it shares: the
// model-to-map transform the renderer draws with, the viewpoint the view sphere weighs (the
// camera's direction in the character's frame), and the viewer's distance along the floor that
// distance triggers use.
//
//   Placement p = spec.placement();                         // anim_authoring reads it from a scene
//   Eigen::Matrix4d m = p.ModelToMap();                     // model space → map
//   Eigen::Vector3d v = p.ViewpointFromCamera(C);           // C = −Rᵀt, the camera centre (map)
//   double d = p.FloorDistance(C);                          // metres on a metric map

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "base/geometry.h"

namespace arview::anim {

struct Placement {
  Anchor anchor;  // character frame → map frame: position, rotation (unit quaternion), scale
  double scale = 1.0;  // asset units → the character frame's (the scene's `scale:`)
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();  // the character's front, model space
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();       // its up, model space

  // translate(position) · rotation · uniform scale (anchor.scale · scale).
  Eigen::Matrix4d ModelToMap() const;
  // The anchor's rotation, normalised.
  Eigen::Matrix3d Rotation() const;
  // The character's up in map coordinates (unit).
  Eigen::Vector3d UpInMap() const;
  // Unit direction from the character to a camera centre given in map coordinates, in the
  // character's frame; the zero vector when the camera sits on the anchor.
  Eigen::Vector3d ViewpointFromCamera(const Eigen::Vector3d& camera_center_map) const;
  // The camera's distance from the anchor along the character's floor: "the viewer comes within
  // 1.5 m" of a standing character means on the ground, not from the eyes to its feet (at eye
  // height that would never be closer than ~1.6 m).
  double FloorDistance(const Eigen::Vector3d& camera_center_map) const;
  // A point of the map in model space (the inverse of ModelToMap): where the camera's centre,
  // the viewer's eyes, is for the character's gaze (anim/gaze.h).
  Eigen::Vector3d MapToModel(const Eigen::Vector3d& point_map) const;
  // Model units to map units: anchor.scale · scale.
  double ModelScale() const { return anchor.scale * scale; }
};

}  // namespace arview::anim
