// MapBuildOptions::Check (base/option_check.h): the bounds COLMAP's stages and the fold retries
// need to run at all; the sensible ranges are the flags' (arview map).

#include "mapping/colmap_pipeline.h"

namespace arview::mapping {

void MapBuildOptions::Check(const OptionNames& names) const {
  RequireOption(max_frames >= 0, names("max_frames"), "0 (no cap) or more", max_frames);
  RequireOption(auto_exhaustive_limit >= 0, names("auto_exhaustive_limit"), "0 or more", auto_exhaustive_limit);
  RequireOption(threads >= -1, names("threads"), "-1 (all cores) or more", threads);
  RequireOption(max_num_features >= 1, names("max_num_features"), "at least 1", max_num_features);
  RequireOption(max_num_orientations >= 1, names("max_num_orientations"), "at least 1", max_num_orientations);
  RequireOption(double_frames_below_px >= 0, names("double_frames_below_px"), "0 (every frame) or more",
                double_frames_below_px);
  // COLMAP's own checks of Mapper.ba_global_images_ratio and the iteration counts.
  RequireOption(ba_global_ratio > 1, names("ba_global_ratio"), "above 1", ba_global_ratio);
  RequireOption(ba_global_max_iterations >= 1, names("ba_global_max_iterations"), "at least 1", ba_global_max_iterations);
  RequireOption(ba_local_max_iterations >= 0, names("ba_local_max_iterations"), "0 or more", ba_local_max_iterations);
  RequireOption(sequential_overlap >= 1, names("sequential_overlap"), "at least 1", sequential_overlap);
  cross_rooms.Check(names.Nested("cross_rooms"));
  RequireOption(fold_retries >= 0, names("fold_retries"), "0 or more", fold_retries);
  // COLMAP's mapper triangulates nothing below 0 degrees; above its own 1.5 the retry would lower nothing.
  RequireOption(gap_retry_angle_deg >= 0 && gap_retry_angle_deg < 1.5, names("gap_retry_angle_deg"),
                "0 (no retry) to below 1.5 (degrees)", gap_retry_angle_deg);
  RequireOption(gap_retry_min_frames >= 1, names("gap_retry_min_frames"), "at least 1", gap_retry_min_frames);
  RequireOption(slurm_chunk >= 0, names("slurm_chunk"), "0 (extraction and matching here) or more", slurm_chunk);
  RequireOption(slurm.time_limit_minutes >= 0, names("slurm.time_limit_minutes"), "0 (the partition's) or more (minutes)",
                slurm.time_limit_minutes);
  if (colmap.empty()) throw OptionError(names("colmap") + ": an empty name: give the COLMAP executable");
  if (scale.from == ScaleFrom::kBoard) {
    RequireOption(scale.board.square > 0, names("scale.board.square"), "above 0 (metres)", scale.board.square);
  }
}

}  // namespace arview::mapping
