#pragma once
// BuildMap's answer to a model that leaves a stretch of the walk out: COLMAP's mapper run once
// more on the same matches with a lower triangulation angle (docs/mapping.md, "A fast turn").
//
// Why: a fast turn (the rendered room's 90 degrees in 0.6 s) shows a new part of the room to only
// the last frame or two before the turn ends, a few centimetres apart. COLMAP's mapper
// triangulates a point only from views at least 1.5 degrees apart (Mapper.tri_min_angle) and
// filters out the ones below it after each adjustment (Mapper.filter_min_tri_angle), so the new
// part has no 3D points, no frame after the turn sees the 30 it needs to be registered
// (Mapper.abs_pose_min_num_inliers), and the rest of the walk is left out. The matches across
// the turn are there (hundreds of inliers per pair): only the points are missing.

#include <filesystem>
#include <string>
#include <vector>

#include "mapping/colmap_pipeline.h"
#include "mapping/fold_retries.h"

namespace arview::mapping {

// A run of consecutive selected frames the model did not register: `first` and `last` are frame
// indices (into the recording), `count` how many selected frames it holds.
struct LeftOutStretch {
  int first = 0;
  int last = 0;
  int count = 0;
};

// The stretches of `selected` (frame indices, increasing, as BuildMap selected them) that no
// keyframe of `map` holds, of at least `min_count` frames each, in order. A frame missing alone
// (blurred, a near-duplicate) is not a stretch unless min_count is 1.
std::vector<LeftOutStretch> LeftOutStretches(const std::vector<int>& selected, const map::Map& map, int min_count);

// The mapper's extra arguments for the retry: both triangulation angles at `angle_deg`.
std::vector<std::string> LowAngleMapperArgs(double angle_deg);

// When the model in `result` leaves out a stretch of at least options.gap_retry_min_frames frames
// (and options.gap_retry_angle_deg > 0), the mapper runs once more with LowAngleMapperArgs; its
// model is kept when it registers more frames and is not folded where the first was not
// (mapping/map_check.h), else the first is put back. The try's model waits in <out>/gap-try/,
// removed after. Returns the extra arguments of the model kept (empty: the first model), which
// later mapper runs (the fold retries) append too. A cancelled try puts the first model back.
std::vector<std::string> RetryLeftOutFrames(const MapBuildOptions& options, const std::filesystem::path& out_dir,
                                            const MapBuildCallbacks& cb, const FoldRetryStages& stages,
                                            MapBuildResult* result);

}  // namespace arview::mapping
