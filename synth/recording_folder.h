#pragma once
// What the rendered recordings (`arview synth room`, `arview synth venue`) share: the folder they
// are written to, and the corners of a textured rectangle.

#include <Eigen/Core>

#include <filesystem>
#include <initializer_list>

#include "synth/synth_room.h"

namespace arview::synth {

// Makes `out` a recording folder with an empty frames/: refused (RenderError) when it is a file
// or holds anything and `overwrite` is false; with `overwrite` only frames/ and `files` (what a
// recording consists of) are removed, never anything else the user keeps there.
void PrepareRecordingFolder(const std::filesystem::path& out, bool overwrite, std::initializer_list<const char*> files);

// A panel's corners (RoomPanel's order: top-left, top-right, bottom-right, bottom-left) for a
// rectangle centred at `centre` spanned by unit `right` and `up`.
void SetPanelCorners(RoomPanel& panel, const Eigen::Vector3d& centre, const Eigen::Vector3d& right, const Eigen::Vector3d& up,
                     double width, double height);

}  // namespace arview::synth
