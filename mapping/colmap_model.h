#pragma once
// Reading COLMAP's output directly: the binary sparse model (cameras.bin, images.bin,
// points3D.bin) and the SQLite feature database (descriptors). Every size and id is validated:
// a truncated or corrupted file throws MapError naming the file and what is wrong. Writing a
// model moved by a similarity (WriteTransformedModel) is in mapping/colmap_model_writer.cpp.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "base/cancellation.h"
#include "calib/camera.h"
#include "calib/pose.h"
#include "map/map.h"
#include "mapping/colmap_database.h"
#include "mapping/map_check.h"

namespace arview::mapping {

// What the recording says about one image COLMAP saw, keyed by COLMAP's image name.
struct FrameInfo {
  int frame_index = -1;
  double timestamp = 0;
};
using FrameLookup = std::map<std::string, FrameInfo>;

constexpr std::uint64_t kInvalidPoint3D = ~std::uint64_t{0};  // a 2D point without a 3D point

// One registered image of a binary sparse model (images.bin), as COLMAP wrote it.
struct ColmapImage {
  std::uint32_t id = 0;
  std::uint32_t camera_id = 0;
  std::string name;
  calib::Pose pose;
  std::vector<Eigen::Vector2d> xy;          // COLMAP convention (OpenCV's pixel + 0.5)
  std::vector<std::uint64_t> point3d_ids;   // kInvalidPoint3D when none
};

struct TrackElement {
  std::uint32_t image_id;
  std::uint32_t point2d_idx;
};

// One 3D point of points3D.bin.
struct ColmapPoint {
  std::uint64_t id = 0;
  map::MapPoint point;
  std::vector<TrackElement> track;
};

// A whole binary sparse model, for the leaves' merge (mapping/leaf_merge.h).
struct SparseModel {
  std::string cameras_bin;  // cameras.bin's bytes, written back as they are
  calib::Camera camera;     // its one camera (arview maps have one)
  std::vector<ColmapImage> images;
  std::vector<ColmapPoint> points;
};

// Reads cameras.bin, images.bin and points3D.bin whole, validated as ReadColmapMap validates
// them (every track refers back to its 2D points). Throws MapError naming the file.
SparseModel ReadSparseModel(const std::filesystem::path& sparse_dir, const CancellationToken& cancel = {});

// Writes `model` as a binary sparse model into the folder `to` (created), each file atomically;
// MapError naming the file that cannot be written.
void WriteSparseModel(const SparseModel& model, const std::filesystem::path& to);

// The number of registered images in a sparse model folder (reads only images.bin's header);
// used to pick the largest of several models. Throws MapError when images.bin is unreadable.
std::uint64_t CountRegisteredImages(const std::filesystem::path& sparse_dir);

// Builds the Map from a sparse model folder and the database it came from. Every registered
// image must appear in `frames` (unless `frames` is empty: then frame_index = -1, timestamp 0).
// Keyframes are ordered by frame index (then name), points by COLMAP's point id.
// Only regular files are read (a link to a device or FIFO is refused), in chunks that look at
// `cancel` (CancelledError). With `keypoints`, it also receives every keypoint of each keyframe
// (OpenCV pixels, in keyframe order), observations of map points or not (for mapping/map_check.h).
// Values beyond what a map may hold (map::kMaxCoordinate, kMaxPixel: a degenerate registration
// far away, a point at 1e11) are refused naming images.bin or points3D.bin, unless
// `check_values` is false: then the caller runs RequireModelValuesInRange itself (arview map
// first looks at the whole map, mapping/map_check.h, so that it can say why).
map::Map ReadColmapMap(const std::filesystem::path& sparse_dir, const std::filesystem::path& database,
                  const FrameLookup& frames = {}, const CancellationToken& cancel = {},
                  std::vector<std::vector<Eigen::Vector2f>>* keypoints = nullptr, bool check_values = true);

// A sparse model read as ReadColmapMap reads it (`check_values` false: the caller runs
// RequireModelValuesInRange) and looked at as a whole (CheckMap with every keyframe's keypoints
// and the database's two-view geometries): how BuildMap judges the mapper's model, and
// `arview map --leaf-size` each leaf's (mapping/leaf_mapping.h).
struct CheckedModel {
  map::Map map;
  MapCheck check;
};
CheckedModel ReadCheckedModel(const std::filesystem::path& sparse_dir, const std::filesystem::path& database,
                              const FrameLookup& frames = {}, const CancellationToken& cancel = {});

// The registered images of a sparse model as keyframes without observations (images.bin alone,
// ordered as ReadColmapMap orders them): for looking at a model's camera path when its database
// is gone. Throws MapError as ReadColmapMap does.
std::vector<map::Keyframe> ReadColmapCameraPath(const std::filesystem::path& sparse_dir, const FrameLookup& frames = {});

// Reads cameras.bin, images.bin and points3D.bin of a sparse model as ReadColmapMap does, without
// the database: a damaged model is a MapError naming its file before anything runs on it
// (`arview map extend`, whose COLMAP stages would otherwise end in COLMAP's stack trace).
void RequireReadableModel(const std::filesystem::path& sparse_dir, const CancellationToken& cancel = {});

// The binary sparse model in `from` moved by `transform` (every image's pose and every point;
// cameras.bin as it is) written into the folder `to` (created), otherwise byte for byte as
// COLMAP wrote it. Each file is written atomically; a file that cannot be written is a MapError
// naming it and the cause ("File too large", "No space left on device"). COLMAP's own
// model_transformer ignores write errors and leaves a truncated model looking complete.
void WriteTransformedModel(const std::filesystem::path& from, const std::filesystem::path& to, const Sim3& transform);

// The SIFT descriptors COLMAP extracted for the named images (one rows x 128 CV_8U matrix each,
// in the order of `names`). Throws MapError naming the database and the image that is missing
// or malformed.
std::vector<cv::Mat> ReadImageDescriptors(const std::filesystem::path& database, const std::vector<std::string>& names,
                                          const CancellationToken& cancel = {});

// The two-view geometries COLMAP verified between the map's keyframes (its database's
// two_view_geometries), for mapping/map_check.h. Pairs with an unregistered frame are left out;
// a database without the table gives none. Throws MapError when the database cannot be opened.
std::vector<TwoViewGeometry> ReadTwoViewGeometries(const std::filesystem::path& database, const map::Map& map);

// Every image of a database (id, name; by id) and every verified pair with inliers, for the match
// graph (mapping/match_graph.h). Throws MapError when the database cannot be read.
struct DatabaseMatchGraph {
  std::vector<std::pair<std::uint32_t, std::string>> images;
  std::vector<VerifiedPair> pairs;
};
DatabaseMatchGraph ReadMatchGraph(const std::filesystem::path& database);

// Every pair of a general motion (COLMAP's CALIBRATED and UNCALIBRATED configurations) with its
// F; the planar and pure-turn pairs, whose F is not defined, are left out.
std::vector<FundamentalPair> ReadFundamentalMatrices(const std::filesystem::path& database);

// Replaces the parameters of the database's one camera (arview maps with a single camera), in
// COLMAP's order for its model. MapError naming the database when it cannot.
void SetSingleCameraParams(const std::filesystem::path& database, const std::vector<double>& params);

// Throws MapError naming the file of `sparse_dir` (images.bin, points3D.bin) that holds the first
// value a map may not hold.
void RequireModelValuesInRange(const map::Map& map, const std::filesystem::path& sparse_dir);

}  // namespace arview::mapping
