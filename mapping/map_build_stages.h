#pragma once
// What `arview map`'s MapBuild (mapping/colmap_pipeline.cpp: BuildMap's stages in the order they
// run, over the state they hand on) runs its stages with, kept apart from it so that the build
// reads as its sequence. Internal to mapping/:
//
//   colmap_stages.cpp   a stage's record (stages/<name>.inputs), COLMAP as a child process with
//                       its progress parsed, COLMAP's command lines, the frames COLMAP gets,
//                       the largest model (also what mapping/colmap_stages.h declares)
//   match_stage.cpp     the match stage done by arview: the pairs matched here, verified by
//                       COLMAP's matches_importer in several processes; its stage records
//   map_folder.cpp      the built map made metric with its COLMAP model; the map folder's files

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "base/cancellation.h"
#include "calib/camera.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/colmap_stages.h"
#include "mapping/metric_frame.h"
#include "mapping/pair_matching.h"
#include "recordings/recording.h"

namespace arview::mapping {

// --- mapping/colmap_stages.cpp ---

// Stage inputs as text: a stage is skipped when the text saved after its last success matches.
class StageRecord {
 public:
  explicit StageRecord(const std::filesystem::path& out_dir) : dir_(out_dir / "stages") {}
  bool Matches(const std::string& stage, const std::string& inputs) const;
  void Forget(const std::string& stage) const;
  void Save(const std::string& stage, const std::string& inputs) const;

 private:
  std::filesystem::path dir_;
};

// COLMAP's command-line tool run as a child process, its output appended to <out_dir>/colmap.log
// and its progress lines handed to cb.progress. Throws map::MapError when no COLMAP is found,
// ColmapStageError when a command fails (map::MapError when the disk is full).
class ColmapRunner {
 public:
  ColmapRunner(const MapBuildOptions& options, const std::filesystem::path& out_dir, const MapBuildCallbacks& cb);

  void Run(const std::string& stage, const std::vector<std::string>& args, int total);
  // The same with its own log file and line handler (several at once: the verifying processes).
  void Run(const std::string& stage, const std::vector<std::string>& args, const std::filesystem::path& log,
           const std::function<void(const std::string&)>& on_line);
  const std::filesystem::path& log() const { return log_; }

 private:
  const MapBuildOptions& options_;
  std::filesystem::path log_;
  const MapBuildCallbacks& cb_;
};

// A file's size and modification time, for a stage's record. Throws map::MapError when it is
// missing.
std::string FileIdentity(const std::filesystem::path& file);

// Numbers as COLMAP's command line takes them (every digit a double holds).
std::string FormatParams(const std::vector<double>& v, const char* separator = ",");

// The frames --frames names (every frame without it). Throws recordings::RecordingError for a bad
// --frames.
std::vector<int> CandidateFrames(const recordings::Recording& rec, const MapBuildOptions& options);

// The select stage. Video: the selected frames written as PNG files under <out>/images (skipped
// when done before with the same selection). Still images: the candidates thinned evenly to
// --max-frames, read where they are. `selected` gets the frame indices.
ImageSet PrepareVideoImages(const recordings::Recording& rec, const std::filesystem::path& out_dir,
                            const MapBuildOptions& options, const MapBuildCallbacks& cb, StageRecord& stages,
                            std::vector<int>* selected);
ImageSet PrepareStillImages(const recordings::Recording& rec, const MapBuildOptions& options, const MapBuildCallbacks& cb,
                            std::vector<int>* selected);

// The sparse model with the most registered images among <out>/sparse/<n>/; `count` gets how
// many models there are (a note names them when several).
std::filesystem::path LargestModel(const std::filesystem::path& sparse_root, int* count, const MapBuildCallbacks& cb);

// Whether COLMAP's SIFT doubles the frames (MapBuildOptions::double_frames_below_px).
bool FramesDoubled(const calib::Camera& camera, const MapBuildOptions& options);

// COLMAP's matcher's command line (exhaustive or sequential, ExhaustiveMatchingWanted).
std::vector<std::string> MatchArgs(const MapBuildOptions& options, const std::filesystem::path& database, int frames);

// --- mapping/match_stage.cpp ---

// arview's matching (mapping/pair_matching.h) needs image names COLMAP's match list can hold:
// matches_importer splits a pair's line at the first space.
bool NamesFitAMatchList(const std::vector<std::string>& names);

// Each image's room (the index in options.rooms of the room holding its frame, -1: none), or
// nothing when options.rooms holds fewer than two rooms.
std::vector<int> RoomOfEachImage(const MapBuildOptions& options, const std::vector<std::string>& names,
                                 const FrameLookup& lookup);

// Whether a venue's frames are paired room by room and across rooms from a descriptor index
// (mapping/venue_pairs.h): two rooms or more, sequential matching, cross_rooms.neighbours > 0.
bool VenuePairsWanted(const MapBuildOptions& options, int frames);

// The pairs `arview map` matches: exhaustive or sequential, as COLMAP's matcher would; a venue's
// (VenuePairsWanted) so within each room, and across rooms from the images' `descriptors` (read
// from `database` when not given). `names` are the images in their order, `lookup` their frames,
// whose room options.rooms says. The venue's pairs are described in a note (cb.note).
std::vector<ImagePair> PairsToMatch(const MapBuildOptions& options, const std::vector<std::string>& names,
                                    const FrameLookup& lookup, const std::filesystem::path& database,
                                    const MapBuildCallbacks& cb, const std::vector<cv::Mat>* descriptors = nullptr);

// COLMAP's matcher on listed pairs (matches_importer --match_type pairs, one process): a venue's
// pairs where COLMAP matches (--match-engine colmap, or frames it doubles).
void MatchListedPairsWithColmap(ColmapRunner& colmap, const std::filesystem::path& database,
                                const std::filesystem::path& out_dir, const std::vector<std::string>& names,
                                const FrameLookup& lookup, const MapBuildOptions& options, const MapBuildCallbacks& cb);

// What decides arview's matches, and the Slurm jobs' (matches_importer on pairs), for the stage
// record.
std::string ArviewMatchInputs(const MapBuildOptions& options, int frames);
std::string SlurmMatchInputs(const MapBuildOptions& options, int frames);
std::string ListedPairsMatchInputs(const MapBuildOptions& options, int frames);  // MatchListedPairsWithColmap's

// arview's matching: the pairs matched with a kd-tree per frame, then verified by COLMAP.
// `timings` gets the two steps.
void MatchWithArview(ColmapRunner& colmap, const std::filesystem::path& database, const std::filesystem::path& out_dir,
                     const std::vector<std::string>& names, const FrameLookup& lookup, const MapBuildOptions& options,
                     const MapBuildCallbacks& cb, std::vector<StageTiming>* timings);

// --- mapping/map_folder.cpp ---

// A frame's grey image, or an empty one when the file cannot be read (the board is then not
// seen in it).
cv::Mat GreyImageOrNone(const std::filesystem::path& file);

// A keyframe's grey image from the folder the map's frames were given to COLMAP from.
KeyframeImages KeyframeImagesIn(const map::Map& map, const std::vector<std::filesystem::path>& roots);

// The built map made metric as options.scale asks (a board that fails: the estimate, and
// result->scale_failure says why), the COLMAP model with it.
// `read_model` reads the moved model back: the map is then exactly what a re-run reads (COLMAP
// rounds the transformed poses its own way), so that the same command again writes the same bytes.
void MakeMetric(const KeyframeImages& images, BoardSearchInBackground* board_search, const MapBuildOptions& options,
                const MapBuildCallbacks& cb, const std::function<map::Map()>& read_model, MapBuildResult* result);

}  // namespace arview::mapping
