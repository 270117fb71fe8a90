#pragma once
// `arview map`: from a recording to a map directory, with COLMAP's command-line tool run as
// child processes (feature_extractor, a matcher, mapper).
//
// The map directory holds COLMAP's own database.db and sparse/<n>/ model (so that the map opens
// in COLMAP's GUI), colmap.log (everything COLMAP printed), keyframes.txt (TUM, camera-to-world,
// the recording's timestamps), map.arvmap (the compact map the tracker loads) and map.png (a top
// view). stages/ remembers the inputs of each finished stage, so that a re-run skips the stages
// whose inputs did not change.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/cancellation.h"
#include "base/enum_table.h"
#include "base/option_check.h"
#include "map/map.h"
#include "mapping/frame_selection.h"
#include "mapping/map_check.h"
#include "mapping/metric_frame.h"
#include "mapping/pair_matching.h"
#include "mapping/slurm_engine.h"
#include "mapping/venue.h"
#include "mapping/venue_pairs.h"
#include "recordings/recording.h"

namespace arview::mapping {

enum class MatcherKind { kAuto, kSequential, kExhaustive };
constexpr auto EnumNames(MatcherKind) {
  return EnumTable<MatcherKind, 3>{{{MatcherKind::kAuto, "auto"},
                                    {MatcherKind::kSequential, "sequential"},
                                    {MatcherKind::kExhaustive, "exhaustive"}}};
}
MatcherKind ParseMatcherKind(const std::string& text);  // throws MapError; back: arview::ToString

// Who matches the frames' features: arview (mapping/pair_matching.h: a kd-tree per frame, then
// COLMAP's geometric verification) or COLMAP's own matcher (a kd-tree per pair). The same pairs
// either way (MatcherKind). kAuto: arview for frames too large to be doubled
// (MapBuildOptions::double_frames_below_px), COLMAP for smaller ones. On phone-fox's 1080x1920
// frames arview's matching was 3.3x faster with keyframes as exact; on templeRing's 640x480
// frames its kd-trees' approximate search (32 leaves per query) left the map at 1.56 mm against
// COLMAP's 1.19 mm, and 128 leaves (1.29 mm) were no faster than COLMAP (docs/mapping.md,
// "Matching").
enum class MatchEngine { kAuto, kArview, kColmap };
constexpr auto EnumNames(MatchEngine) {
  return EnumTable<MatchEngine, 3>{
      {{MatchEngine::kAuto, "auto"}, {MatchEngine::kArview, "arview"}, {MatchEngine::kColmap, "colmap"}}};
}
MatchEngine ParseMatchEngine(const std::string& text);  // throws MapError

// Where the leaves of a map built in parts are mapped (MapBuildOptions::leaf_size,
// mapping/leaf_mapping.h): one after another as child processes, or as jobs on a Slurm cluster
// (mapping/slurm_engine.h).
enum class MapEngine { kLocal, kSlurm };
constexpr auto EnumNames(MapEngine) {
  return EnumTable<MapEngine, 2>{{{MapEngine::kLocal, "local"}, {MapEngine::kSlurm, "slurm"}}};
}
MapEngine ParseMapEngine(const std::string& text);  // throws MapError (mapping/leaf_mapping.cpp)

// Where a map's metres and up come from (mapping/metric_frame.h).
enum class ScaleFrom { kNone, kBoard, kKnownDistance, kCameraHeight };

struct ScaleRequest {
  ScaleFrom from = ScaleFrom::kNone;
  BoardSpec board;                              // kBoard
  std::vector<PointSighting> point_a, point_b;  // kKnownDistance: each end's pixels
  double distance_m = 0;                        // kKnownDistance
};

struct MapBuildOptions {
  std::string frames_spec;  // recordings::ParseFrameSpec syntax; empty: every frame
  MatcherKind matcher = MatcherKind::kAuto;
  int auto_exhaustive_limit = 100;  // kAuto: exhaustive up to this many frames, sequential above
  int max_frames = 300;             // cap on the frames given to COLMAP (0: none)
  FrameSelectionOptions selection;  // video recordings only (its max_frames is ignored)
  bool refine_intrinsics = false;   // let COLMAP's bundle adjustment refine the camera
  int threads = 2;                  // COLMAP's threads per stage (-1: all cores)
  // Feature and bundle-adjustment settings. The defaults are COLMAP's own (the "quality" preset:
  // templeRing's odd frames then localise at about 0.9 mm, as COLMAP registers them); the "fast"
  // preset trades accuracy for time (docs/mapping.md, "Presets"). COLMAP 3.8 matches on the CPU
  // by building a FLANN kd-tree per image and pair, so matching time grows with the number of
  // descriptors per image.
  int max_num_features = 8192;       // SiftExtraction.max_num_features
  int max_num_orientations = 2;      // SiftExtraction.max_num_orientations
  // COLMAP's SIFT first doubles each frame (SiftExtraction.first_octave -1) to find the finest
  // features. Frames this long or longer are not doubled: a 1080x1920 phone frame doubled is
  // 8 megapixels, extraction took 3.5 s a frame, and the features it added were the ones the
  // 8,192 cap then dropped; not doubling took extraction from 60 s to 24 s on phone-fox with a
  // map as exact (docs/mapping.md, "Matching"). 0: every frame is doubled, as COLMAP does.
  int double_frames_below_px = 1600;
  MatchEngine match_engine = MatchEngine::kAuto;
  PairMatchingOptions pair_matching;  // MatchEngine::kArview (its threads are `threads`)
  double ba_global_ratio = 1.1;      // Mapper.ba_global_images_ratio and _points_ratio
  int ba_global_max_iterations = 50; // Mapper.ba_global_max_num_iterations
  int ba_local_max_iterations = 25;  // Mapper.ba_local_max_num_iterations
  int sequential_overlap = 10;       // SequentialMatching.overlap
  bool quadratic_overlap = true;     // SequentialMatching.quadratic_overlap: loop-like long links
  std::vector<std::string> extra_mapper_args;  // appended to the mapper's command line
  // When the self-check finds a fold (mapping/map_check.h: part of the path registered at wrong
  // rotations), COLMAP's mapper runs again on the same matches, up to this many times, each time
  // started from a keyframe the check found right (a fold starts at the mapper's initial pair: on
  // phone-fox two of four default builds began with frames 2 and 10 and folded frames 0-8). A map
  // still folded after them is refused (BuildMap throws MapError, check.json says why) unless
  // keep_folded: then the least folded model is written, with the warning.
  int fold_retries = 2;
  bool keep_folded = false;
  // When the model leaves out a stretch of at least gap_retry_min_frames consecutive selected
  // frames (the walk after a fast turn: mapping/gap_retry.h), COLMAP's mapper runs once more on
  // the same matches with both triangulation angles (Mapper.tri_min_angle,
  // filter_min_tri_angle; COLMAP's 1.5) at gap_retry_angle_deg, and the model registering more
  // frames is kept. 0: no retry. A map that registers every frame never runs it.
  double gap_retry_angle_deg = 0.5;
  int gap_retry_min_frames = 3;
  // A venue in parts (mapping/leaf_mapping.h): with more frames than leaf_size, the match graph
  // is cut into leaves of at most leaf_size frames (METIS on the inliers), each grown by
  // leaf_overlap frames most strongly tied to it; each leaf is mapped alone (on `engine`) and
  // the leaves merged (mapping/leaf_merge.h, then point_triangulator, bundle_adjuster). The fold
  // retries apply to each leaf, not to the merged map. 0: one mapper over every frame (today's path).
  int leaf_size = 0;
  int leaf_overlap = 10;
  // A venue's leaves cut within its rooms (PartitionOptions::room_of); off: METIS over every
  // frame, the rooms unknown to it (on the rendered venue one run each way, within rooms was
  // not the better: docs/mapping.md, "Leaves within rooms").
  bool leaves_within_rooms = false;
  // Whether the leaves are cut within rooms: asked for, and a venue of two rooms or more.
  bool LeavesCutWithinRooms() const { return leaves_within_rooms && rooms.size() >= 2; }
  MapEngine engine = MapEngine::kLocal;
  SlurmOptions slurm;
  // With engine kSlurm: feature extraction and matching as Slurm jobs of about this many frames
  // each (mapping/job_stages.h); 0: they run here, as with kLocal.
  int slurm_chunk = 0;
  // The map made metric and upright before it is written (the COLMAP model too). A board that
  // cannot be used falls back to the camera-height estimate, and MapBuildResult::scale_failure
  // says why; with kCameraHeight, a map without a floor stays in COLMAP's frame (a note says so).
  ScaleRequest scale;
  // A venue's rooms (mapping/venue.h, VenueRecording): the map file names each keyframe's room.
  // Empty for one recording.
  std::vector<VenueRoom> rooms;
  // A venue matched sequentially: each room's frames among themselves, and each frame with the
  // frames of other rooms that share most of its descriptors (mapping/venue_pairs.h; its threads
  // are `threads`).
  CrossRoomOptions cross_rooms;

  // `arview map --preset fast`: 850 features and one orientation per keypoint, fewer bundle
  // adjustments (chosen on templeRing: a third less CPU, about twice the tracking error).
  void UseFastPreset() {
    max_num_features = 850;
    max_num_orientations = 1;
    ba_global_ratio = 1.3;
    ba_global_max_iterations = 25;
    ba_local_max_iterations = 15;
  }
  std::string colmap = "colmap";    // the COLMAP executable (found on PATH)
  // Cancelled (Ctrl-C, SIGTERM): the running COLMAP stage is stopped, BuildMap throws
  // CancelledError, and the stages finished before stay recorded for a re-run.
  CancellationToken cancel;

  // Throws OptionError naming the first bad field (base/option_check.h); BuildMap and ExtendMap
  // call it before anything is written (mapping/map_build_options.cpp).
  void Check(const OptionNames& names = {}) const;
};

// A COLMAP stage that failed: the message says which and why; `log_tail` holds the last lines
// COLMAP printed (the full output is in `log`).
struct ColmapStageError : map::MapError {
  ColmapStageError(const std::string& message, std::string stage_name, std::filesystem::path log_file,
                   std::vector<std::string> tail)
      : map::MapError(message), stage(std::move(stage_name)), log(std::move(log_file)), log_tail(std::move(tail)) {}
  std::string stage;
  std::filesystem::path log;
  std::vector<std::string> log_tail;
};

struct MapBuildCallbacks {
  // Stage progress: stage is "select", "extract", "match", "verify" or "map"; total may be 0
  // (unknown).
  std::function<void(const std::string& stage, int done, int total)> progress;
  // Things the user should know (a skipped stage, several models, dropped frames).
  std::function<void(const std::string& message)> note;
  // What the map's self-check found wrong (mapping/map_check.h), one sentence each, before the
  // map is written (or refused for a value out of range).
  std::function<void(const std::string& message)> warning;
};

struct StageTiming {
  std::string stage;
  double seconds = 0;
  bool skipped = false;
};

struct MapBuildResult {
  map::Map map;
  std::vector<int> selected_frames;  // indices into the recording's frames.txt
  std::vector<StageTiming> timings;
  int models = 0;                    // models COLMAP produced
  std::filesystem::path model_dir;   // the one kept (the largest)
  MapCheck check;                    // what the map looks like as a whole (also in <out>/check.json)
  int fold_retries = 0;              // times the mapper ran again for a fold
  std::string scale_failure;         // why the requested scale source could not be used; empty: it was
};

// Runs everything and writes the map directory. Throws MapError (or ColmapStageError,
// arview::CancelledError when options.cancel is cancelled, arview::ProcessError when COLMAP
// cannot be started, recordings::RecordingError for a bad --frames).
MapBuildResult BuildMap(const recordings::Recording& recording, const std::filesystem::path& out_dir,
                        const MapBuildOptions& options, const MapBuildCallbacks& callbacks = {});

// The self-check of a map folder that `arview map` wrote (mapping/map_check.h) computed again
// from the COLMAP model and database kept there, and written to its check.json: for maps built
// before a check existed, or after its limits changed. Throws MapError naming what is missing.
MapCheck RecheckMap(const std::filesystem::path& map_dir);

// `arview map scale`: a map folder that `arview map` wrote made metric and upright afterwards
// (map.arvmap, the COLMAP model, keyframes.txt, map.png, check.json's distances), from a board
// seen in its keyframes or a known distance. `recording` is where a still-image map's keyframe
// images are (a video map keeps its own in <map-dir>/images; may be null then). Nothing is
// changed when it fails (MapError says why). Returns the map as written.
map::Map ScaleMapFolder(const std::filesystem::path& map_dir, const recordings::Recording* recording,
                        const ScaleRequest& request, const MapBuildOptions& options,
                        const MapBuildCallbacks& callbacks = {});

// One line of COLMAP 3.8's output as progress (done, total), or nothing: "Processed file [i/N]",
// "Matching image [i/N]", "Matching block [a/A, b/B]", "Registering image #id (n)" (n of
// `total_images`), "Initializing with image pair".
std::optional<std::pair<int, int>> ParseColmapProgress(const std::string& line, int total_images);

// The keyframes as a TUM trajectory (camera-to-world, the recording's timestamps).
void WriteKeyframesTum(const map::Map& map, const std::filesystem::path& file);

// A top view of the map: the points (their colours) seen along the axis normal to the plane the
// cameras move in, with the camera path drawn over them. Throws MapError when it cannot write.
void WriteTopView(const map::Map& map, const std::filesystem::path& png, int size = 800);

}  // namespace arview::mapping
