#pragma once
// `arview map --leaf-size N`: COLMAP's mapper run on leaves of the match graph instead of every
// frame at once, and the leaves merged, as COLMAP's hierarchical mapper does, so that the leaves
// can run on several machines (`--engine slurm`, mapping/slurm_engine.h). Internal to mapping/:
// BuildMap's map stage calls it in place of the one mapper.
//
//   partition   the database's match graph cut with METIS (mapping/match_graph.h)
//   leaves      <out>/leaves/<i>/images.txt, COLMAP mapper on those images (one model:
//               --Mapper.multiple_models 0) ─► <out>/leaves/<i>/sparse/0; each leaf's model
//               checked as a map is (mapping/map_check.h), and one that registered under half
//               its frames or folded mapped again from other starts (RetryLeafModels)
//   merge       leaf by leaf (each next the leaf sharing the most images with those merged), on
//               the shared frames' 3D points (mapping/leaf_merge.h), in this process ─►
//               <out>/leaves/merged; then point_triangulator (the leaves' points kept and
//               completed from the database's matches) and bundle_adjuster over everything,
//               twice (on `engine`: with slurm, a job and the job after it) ─► <out>/leaves/adjusted
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

// What the retries of the leaves' models work with: a leaf's model read and checked into a
// result (false: the leaf has no model), the leaf's mapper run once more with arguments appended
// (its model in <leaf dir>/sparse/0), and the log holding its runs' initial pairs.
struct LeafRetryStages {
  std::function<bool(int leaf, MapBuildResult* result)> read_and_check;
  std::function<void(int leaf, const std::vector<std::string>& extra_args)> map_again;
  std::function<std::filesystem::path(int leaf)> log_of;
};

struct LeafToRetry {
  std::string name;            // "leaf 6 (161 frames)"
  std::filesystem::path dir;   // its model in <dir>/sparse/0
  int frames = 0;
  // Frames to start a new mapper run from (COLMAP image id, frame name), the best matched within
  // the leaf first.
  std::vector<std::pair<std::uint32_t, std::string>> starts;
};

// Each leaf's model looked at, as BuildMap looks at one mapper's:
//  - a model that registered under half the leaf's frames, or no model (COLMAP's mapper stopped
//    early: the rendered venue's leaf 6 once kept 7 of its 161), is mapped again from the best-matched frame
//    it left out (--Mapper.init_image_id1), up to options.fold_retries times, the model
//    registering most kept;
//  - a folded model (mapping/map_check.h) is mapped again from other starts
//    (mapping/fold_retries.h: up to options.fold_retries runs, the least folded model kept). A
//    leaf still folded is a MapError naming it (its check.json written in its folder) unless
//    options.keep_folded.
// Notes name the leaf.
void RetryLeafModels(const MapBuildOptions& options, const std::vector<LeafToRetry>& leaves, const MapBuildCallbacks& cb,
                     const LeafRetryStages& stages);

}  // namespace arview::mapping
