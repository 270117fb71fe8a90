#pragma once
// What the map's keyframes look like (brightness, blur), from their images, so that a lost
// frame can be called too dark or blurred against them (tracker/loss_diagnosis.h). The map file
// holds no pixels; the images are where `arview map` left them: <map>/images for a video
// recording's map, the recording's own frames for a still-image map. Only read: the map folder
// is never written (docs/mapping.md, "Localize only").

#include <filesystem>
#include <span>

#include "map/map.h"
#include "recordings/recording.h"
#include "tracker/loss_diagnosis.h"

namespace arview::app {

// The map's folder from what names the map on the command line (the folder, or its map.arvmap).
std::filesystem::path MapFolder(const std::string& map_name);

// The medians over up to `max_images` keyframes spread over the map, each looked for as
// <map_dir>/images/<name>, <map_dir>/<name>, then in `recording` (a replay's; may be null) when
// it is the one the map was built from: its frame at the keyframe's index has the keyframe's
// name and timestamp (another lap of the same room names its frames alike, but they are not
// the map's). Unreadable or missing images are skipped; none found: images == 0.
tracker::AppearanceReference KeyframeAppearance(const map::Map& map, const std::filesystem::path& map_dir,
                                                const recordings::Recording* recording, int max_images = 8);

}  // namespace arview::app
