#pragma once
// `run` and `replay` without --scene: the built-in figure, stood on the map's floor in front of
// the first localized view as `arview place` would stand it, and the one line that says where
// and how to keep it (docs/app.md, "First run without a scene").

#include <optional>
#include <string>

#include "app/session/ar_session.h"
#include "map/map.h"

namespace arview::app {

// The figure placed where `arview place <map_dir> --character builtin:figure` stands it (the
// map's floor, its keys), to be moved in front of the first localized view. A map without a
// floor that place can find: one `note:` line on stderr and nothing (the session goes on with
// the video and the tracking only).
std::optional<FirstViewCharacter> FirstRunFigure(const map::Map& map, const std::string& map_dir);

// The line said when the figure stands: where (map metres, or map units on a map without
// scale), how far in front of the view, what it took, and the `arview place` command that
// writes the same scene.
std::string FirstRunFigureLine(const map::Map& map, const std::string& map_dir, const Anchor& anchor,
                               const calib::Pose& view, double milliseconds);

}  // namespace arview::app
