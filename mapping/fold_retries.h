#pragma once
// BuildMap's answer to a folded model (mapping/map_check.h): COLMAP's mapper run again from other
// starts, and the one line a map still folded is refused with (docs/mapping.md, "A fold in a real
// map").

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mapping/colmap_pipeline.h"

namespace arview::mapping {

// What the retries do through BuildMap's stages.
struct FoldRetryStages {
  // The map stage, `extra_args` appended to the mapper's command line.
  std::function<void(const std::vector<std::string>& extra_args)> map;
  std::function<void()> read_model;  // the largest model read and checked into the result
  std::function<void()> forget_map;  // the map stage's record removed (its model is set aside)
  std::function<void()> remember_map;  // the map stage recorded as done (for the model put back)
};

// A folded map (mapping/map_check.h): COLMAP's mapper runs again on the same matches, up to
// `retries` times, each time started from a keyframe the check found right
// (--Mapper.init_image_id1, KeyframeToStartFrom), never from an image an earlier run started from.
// A fold starts at the initial pair: two of four default builds of phone-fox started from frames 2
// and 10 (a flat view), and both folded frames 0-8; the same matches mapped from another start gave
// the right map (docs/mapping.md, "A fold in a real map"). The mapper alone costs a fraction of
// matching again. Each try's model waits in <out>/fold-tries/<n>/; the best (FoldsLess) is left in
// place and the folder removed. A try that fails ends the retries; a cancelled one puts the best
// back before it stops. `stages.remember_map` records the map stage as done for the model put back.
void RetryFoldedMap(int retries, const std::filesystem::path& out_dir, const std::filesystem::path& log,
                    const MapBuildCallbacks& cb, const FoldRetryStages& stages, MapBuildResult* result);

// The one line `arview map` refuses a folded map with.
std::string FoldRefusal(const std::filesystem::path& out_dir, const MapBuildResult& result);

}  // namespace arview::mapping
