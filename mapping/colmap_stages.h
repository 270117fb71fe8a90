#pragma once
// The parts of `arview map` (mapping/colmap_stages.cpp, map_folder.cpp) that `arview map extend`
// (mapping/map_extend.h) runs as well: frame selection, COLMAP's command lines and child
// processes, the database copy, and the map folder's files. Internal to mapping/.

#include <filesystem>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_pipeline.h"
#include "recordings/recording.h"

namespace arview::mapping {

// The images COLMAP reads: a folder and names relative to it, with each name's frame.
struct ImageSet {
  std::filesystem::path root;
  std::vector<std::string> names;
  FrameLookup lookup;
};

// `arview map`'s frame selection (--frames, --max-frames; a video's frames written as PNG under
// <out_dir>/images, its stage record in <out_dir>/stages). `selected` gets the frame indices.
ImageSet SelectImages(const recordings::Recording& recording, const std::filesystem::path& out_dir,
                      const MapBuildOptions& options, const MapBuildCallbacks& cb, std::vector<int>* selected);

// One COLMAP command as a child process (output appended to <out_dir>/colmap.log, progress lines
// to cb.progress as `stage` with `total` images, stopped by options.cancel). Throws as BuildMap.
void RunColmap(const MapBuildOptions& options, const std::filesystem::path& out_dir, const std::string& stage,
               const std::vector<std::string>& args, int total, const MapBuildCallbacks& cb);

// COLMAP's feature_extractor and mapper command lines as `arview map` runs them. An uncalibrated
// camera (calib::Camera::calibrated false) starts as COLMAP's RADIAL model, and `self_calibrate`
// lets the mapper refine its focal length, principal point and radial terms
// (mapping/self_calibration.h).
std::vector<std::string> ColmapExtractArgs(const calib::Camera& camera, const MapBuildOptions& options,
                                           const std::filesystem::path& database,
                                           const std::filesystem::path& image_root,
                                           const std::filesystem::path& image_list);
std::vector<std::string> ColmapMapperArgs(const MapBuildOptions& options, const std::filesystem::path& database,
                                          const std::filesystem::path& image_root,
                                          const std::filesystem::path& sparse, bool self_calibrate = false);

// Whether `arview map` matches this many frames exhaustively (--matcher), else sequentially.
bool ExhaustiveMatchingWanted(const MapBuildOptions& options, int frames);

// CopyColmapDatabase and RemoveColmapDatabase: mapping/colmap_database.h.

// The model with the most registered images among <sparse_root>/<n>/ (empty when none).
std::filesystem::path LargestColmapModel(const std::filesystem::path& sparse_root);

// check.json, keyframes.txt, map.png and map.arvmap last, each written atomically.
void WriteMapFiles(const MapBuildResult& result, const std::filesystem::path& out_dir, const MapBuildOptions& options,
                   const MapBuildCallbacks& cb);

}  // namespace arview::mapping
