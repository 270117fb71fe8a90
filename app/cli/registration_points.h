#pragma once
// The scene points `arview eval` projects to measure registration in pixels: each character's
// anchor (where it stands) and the eight corners of its rest pose's bounding box, in the map's
// frame; or points listed in a text file.

#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "anim/character.h"
#include "anim/placement.h"

namespace arview::app {

// The anchor first, then the box's corners mapped by the placement. Throws arview::Error when
// the character has neither vertices nor joints.
std::vector<Eigen::Vector3d> CharacterMarks(const anim::Character& character, const anim::Placement& placement);

// Every character of the scene file (their assets loaded), the first character's anchor first.
std::vector<Eigen::Vector3d> SceneMarks(const std::filesystem::path& scene);

// "x y z" a line in the map's frame, '#' starts a comment; throws arview::Error naming the file
// and line of anything else, or a file without points.
std::vector<Eigen::Vector3d> ReadPointsFile(const std::filesystem::path& file);

// Points on the true surfaces of a room rendered by `arview synth room`, in its world (the
// ground truth's): the corners, edge midpoints and centre of every photo on its walls, floor,
// ceiling and boxes. The room's light (which decides whether a window replaces a photo) is read
// from the ground truth's header; a file without `arview synth room`'s header is refused, naming
// it. `photos`: the folder MakeRoomScene reads (opencv-doc's examples).
std::vector<Eigen::Vector3d> RoomGeometryPoints(const std::filesystem::path& groundtruth,
                                                const std::filesystem::path& photos);

}  // namespace arview::app
