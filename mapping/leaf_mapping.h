#pragma once
// `arview map --leaf-size N`: COLMAP's mapper run on leaves of the match graph instead of every
// frame at once, and the leaves merged, as COLMAP's hierarchical mapper does, so that the leaves
// can run on several machines (`--engine slurm`, mapping/slurm_engine.h). Internal to mapping/:
// BuildMap's map stage calls it in place of the one mapper.
//
//   partition   the database's match graph cut with METIS (mapping/match_graph.h)
//   leaves      <out>/leaves/<i>/images.txt, COLMAP mapper on those images (one model:
//               --Mapper.multiple_models 0) ─► <out>/leaves/<i>/sparse/0; each leaf's model
//               checked as a map is (mapping/map_check.h), and a folded one mapped again from
//               other starts (mapping/fold_retries.h; refused unless --keep-folded)
//   merge       leaf by leaf (each next the leaf sharing the most images with those merged), on
//               the shared frames' 3D points (mapping/leaf_merge.h), in this process ─►
//               <out>/leaves/merged; then point_triangulator (the leaves' points kept and
//               completed from the database's matches) and bundle_adjuster over everything
//               (on `engine`: with slurm, a job and the job after it) ─► <out>/leaves/adjusted
//   check       the adjusted model holds every merged image; then <out>/sparse is replaced by it
//
// On any failure <out>/sparse is left as it was; the logs stay in <out>/leaves.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mapping/colmap_pipeline.h"
#include "mapping/match_graph.h"

namespace arview::mapping {

struct LeafMappingPaths {
  std::filesystem::path database;    // the extracted and matched COLMAP database
  std::filesystem::path image_root;  // the images COLMAP reads
  std::filesystem::path out_dir;     // the map folder: leaves/ and sparse/ in it
  FrameLookup frames;                // each image's frame (for the leaves' checks and notes)
};

// Maps the leaves on options.engine and merges them into <out_dir>/sparse/0; `steps` receives
// the time of the leaves and of the merge. Throws MapError naming the leaf or merge step that
// failed and why (ColmapStageError, SlurmError), CancelledError.
void MapInLeaves(const MapBuildOptions& options, const LeafMappingPaths& paths, const MapBuildCallbacks& cb,
                 std::vector<StageTiming>* steps);

// The order the leaves are merged in: leaf 0 first, then each time the leaf sharing the most
// images (core and overlap) with those merged so far.
std::vector<int> MergeOrder(const Partition& partition);

// What the leaves' fold retries work with: a leaf's model read and checked into a result (false:
// the leaf has no model), the leaf's mapper run once more with arguments appended (its model in
// <leaf dir>/sparse/0), and the log holding its runs' initial pairs.
struct FoldedLeafStages {
  std::function<bool(int leaf, MapBuildResult* result)> read_and_check;
  std::function<void(int leaf, const std::vector<std::string>& extra_args)> map_again;
  std::function<std::filesystem::path(int leaf)> log_of;
};

// Each leaf's model checked as a map is (mapping/map_check.h); a folded one mapped again from
// other starts as BuildMap does for one mapper (mapping/fold_retries.h: up to
// options.fold_retries runs, the least folded model kept, notes naming the leaf). A leaf still
// folded is a MapError naming it (its check.json written in its folder) unless
// options.keep_folded.
void RetryFoldedLeaves(const MapBuildOptions& options, const std::vector<std::string>& leaf_names,
                       const std::vector<std::filesystem::path>& leaf_dirs, const MapBuildCallbacks& cb,
                       const FoldedLeafStages& stages);

}  // namespace arview::mapping
