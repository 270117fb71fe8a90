#pragma once
// The frames given to `arview map extend` that the map holds already (the same frames given twice):
// found by their image's bytes, byte for byte a keyframe's image in the map folder. Internal to
// mapping/ (mapping/map_extend.cpp).

#include <filesystem>
#include <vector>

#include "map/map.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/colmap_stages.h"
#include "recordings/recording.h"

namespace arview::mapping {

// `selected` without the frames the map holds already (a note through `cb` names them; all of
// them: a map::MapError, before anything is extracted), and `selected_frames` with it. A
// keyframe's image is looked for under <map_dir>/images, then <map_dir>.
ImageSet WithoutFramesInMap(const ImageSet& selected, const map::Map& map, const std::filesystem::path& map_dir,
                            const recordings::Recording& recording, const MapBuildCallbacks& cb,
                            std::vector<int>* selected_frames);

}  // namespace arview::mapping
