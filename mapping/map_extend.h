#pragma once
// `arview map extend <map-dir> <recording>`: a new session (another day's light, a moved chair, a
// new corner of the room) registered into a map `arview map` built, without mapping again.
//
// The new frames are selected as `arview map` selects them, their SIFT extracted into (a copy
// of) the map's database with the map's own camera, matched with each other and with the old
// keyframes that share most descriptors with them, and COLMAP's incremental mapper continues the
// map's sparse model from where it stood (--input_path) with every old keyframe's pose held
// constant (--Mapper.fix_existing_images): registration, triangulation and bundle adjustment of
// the new frames and the points. COLMAP 3.8's mapper then moves its model to a normalised place
// (a shift and a scale, never a rotation); the extension maps it back onto the old keyframes'
// centres, so the map keeps its frame and scale (a metric, z-up map stays metric and z-up), and
// measures what is left as the old keyframes' drift.
//
// Everything is done in <map-dir>/extend.partial/; the map folder changes only once all of it
// succeeded, file by file with renames, map.arvmap last. A failure or Ctrl-C removes the
// partial folder and leaves the map as it was.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "base/geometry.h"
#include "map/map.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/map_check.h"
#include "recordings/recording.h"

namespace arview::mapping {

struct MapExtendOptions {
  // --frames, --max-frames, --matcher (the new frames among themselves), --threads, --colmap,
  // cancel. Extraction takes the map's own SIFT settings (its stages/extract.inputs, or the last
  // extension's record) unless max_features_set.
  MapBuildOptions build;
  bool max_features_set = false;
  // Old keyframes each new frame is matched with: those whose descriptors are the nearest
  // neighbours of most of the new frame's (a ratio test over the map's descriptor index). The
  // new session's place in the old map is unknown, and matching every new frame with every
  // keyframe costs COLMAP about 0.1 s a pair at 2,048 features.
  int old_neighbours = 10;
};

// An old keyframe's support before and after the extension.
struct KeyframeSupport {
  int frame_index = -1;
  std::string name;
  int observations_before = 0;
  int observations_after = 0;
  double seen_again = 0;  // of its points after, the fraction a new-session keyframe observes too
};

// The extension's outcome, also written to <map-dir>/extend.json.
struct MapExtendResult {
  map::Map map;                      // the extended map (map.arvmap)
  MapCheck check;                    // its self-check (check.json)
  std::string session;               // "session-2": its images are under <map-dir>/images/<session>/
  std::vector<int> selected_frames;  // frames of the new recording given to COLMAP
  int registered = 0;                // of them, registered
  int old_keyframes = 0;             // keyframes before
  int old_keyframes_kept = 0;        // of them, still registered (all, with their poses held)
  std::size_t points_before = 0;
  std::size_t points_after = 0;
  std::size_t points_new_session_only = 0;  // points only new-session keyframes observe
  double drift_max = 0;              // largest move of an old keyframe's centre, map units
  double drift_rotation_max_deg = 0; // largest turn of an old keyframe
  double path_extent = 0;            // the old keyframes' largest centre distance (drift's scale)
  double colmap_shift_scale = 1;     // the scale COLMAP's normalisation had applied (undone)
  std::vector<KeyframeSupport> old_support;       // every old keyframe still registered
  std::vector<KeyframeSupport> no_longer_match;   // those that lost a quarter of their observations or more
  std::vector<StageTiming> timings;
};

inline constexpr const char* kExtendRecordName = "extend.json";
inline constexpr const char* kExtendPartialName = "extend.partial";

// Extends the map in `map_dir` with frames of `recording`. Throws map::MapError naming what is
// wrong before anything is written (no such folder, no map.arvmap, no database.db or COLMAP
// model, a recording of another camera size), ColmapStageError, CancelledError (the map left
// as it was), recordings::RecordingError for a bad --frames.
MapExtendResult ExtendMap(const std::filesystem::path& map_dir, const recordings::Recording& recording,
                          const MapExtendOptions& options, const MapBuildCallbacks& callbacks = {});

// The extended map: `model` (camera, keyframes, points, descriptors read from the extended COLMAP
// model) with every other record `old_map` carries, such as its metric frame: the extension holds
// the old frame, so whatever says what that frame is stays true. A venue's rooms stay: the old
// keyframes keep theirs (by name), the new ones are in none.
map::Map CarryFrameRecord(const map::Map& old_map, map::Map model);

// The similarity from the frame of COLMAP's model to the frame of the map file, found on the
// keyframes both hold (`model_path`: ReadColmapCameraPath of the model), or nothing when they are
// the same frame (a map as `arview map` writes it: the file is read from the model). A map file
// moved into another frame after COLMAP (made metric and z-up, say) while the model stayed has its
// extension moved the same way. Throws map::MapError when no similarity maps the one onto the
// other (within 1e-6 of the path's extent).
std::optional<Sim3> MapFileFrameOfModel(const std::vector<map::Keyframe>& model_path, const map::Map& map_file);

// MapFileFrameOfModel for the model in `model_dir` (its sparse/<n>/) and the map file of
// `map_dir`, once the model is known to be the map's own: every keyframe of the map file is one of
// its images, by id and name. Throws map::MapError naming the model's folder and the map file
// otherwise (another map's model copied in), before anything is written: `map extend` and
// `map scale` refuse such a folder alike.
std::optional<Sim3> RequireOwnModel(const std::filesystem::path& model_dir, const map::Map& map_file,
                                    const std::filesystem::path& map_dir);

// The scale s and shift c that best map `from` onto `to` (to ≈ s·from + c, least squares, no
// rotation): what COLMAP's normalisation did to the old keyframes' centres, inverted.
Sim3 FitScaleAndShift(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

}  // namespace arview::mapping
