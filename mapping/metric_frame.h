#pragma once
// A map in metres with +z up (docs/mapping.md, "Metric scale and up"). COLMAP's model has an
// arbitrary scale and orientation; the similarity that takes it to metres and upright comes from
// what the user has, best first:
//   1. a chessboard of known square size seen in the keyframes: its corners found in the keyframe
//      images, triangulated with the keyframes' poses and fitted to the board's true grid. Scale
//      from its size; when it lies on the floor, up from its normal and the origin at its centre.
//   2. a known distance between two scene points, each given as its pixel in two or more
//      keyframes: scale from the distance, up and origin from the floor.
//   3. an estimate: the floor (the lowest dense plane of the points, below the cameras) and a
//      typical hand-held camera height over it. Stated as an estimate, with its likely error, or
//      refused when the floor found cannot be trusted.
//
//   std::vector<BoardSighting> seen = FindBoard(map, images, {9, 6});
//   MetricFit fit = FitFromBoard(map, TriangulateBoard(map, seen, {9, 6}), {{9, 6}, 0.025});
//   ApplyMetricFit(fit, &map);   // the keyframes, the points and map.frame
//
// The COLMAP model on disk is moved with it (colmap_model.h's WriteTransformedModel, from
// map_folder.cpp). The floor the estimate stands on: mapping/floor_search.h.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "base/cancellation.h"
#include "base/geometry.h"
#include "map/map.h"

namespace arview::mapping {

struct BoardSpec {
  cv::Size inner_corners{9, 6};  // per row, per column
  double square = 0.025;         // metres
  // On the floor: up is its normal and the origin its centre. Elsewhere (a wall): the board
  // gives the scale only, up and the origin come from the floor.
  bool on_floor = true;
};

// The board's inner corners in one keyframe's image: pixels (OpenCV convention), in the order
// calib::FindChessboardCorners gave them.
struct BoardSighting {
  std::size_t keyframe = 0;  // index into Map::keyframes
  std::vector<Eigen::Vector2d> corners;
};

struct TriangulatedBoard {
  std::vector<Eigen::Vector3d> corners;  // the map's frame, row after row
  std::vector<std::size_t> keyframes;    // the sightings kept (indices into Map::keyframes)
  int sightings_dropped = 0;             // sightings whose corners did not agree with the others
  double rms_reprojection_px = 0;        // over the kept sightings' corners
  double widest_angle_deg = 0;           // the widest angle at the board's centre between two kept views
};

// The grey image of a keyframe, or an empty Mat when it cannot be read.
using KeyframeImages = std::function<cv::Mat(std::size_t keyframe)>;

// Looks for the whole board in every keyframe's image. `progress(done, total)` per keyframe.
std::vector<BoardSighting> FindBoard(const map::Map& map, const KeyframeImages& images, cv::Size inner_corners,
                                     const std::function<void(int, int)>& progress = {},
                                     const CancellationToken& cancel = {});

// The board looked for in a set of images while the caller does other work (arview map: while
// COLMAP maps, which leaves a third of two cores unused): on `threads` threads at the lowest
// priority (nice 19), so that they take mostly CPU time nothing else wants. The map's keyframes
// are not known before COLMAP has mapped, so every image given is searched.
//
//   BoardSearchInBackground search(names, read, {9, 6}, 2);
//   ... COLMAP's stages ...
//   std::vector<BoardSighting> seen = search.Sightings(map, progress, cancel);
//
// Stopped and joined when destroyed.
class BoardSearchInBackground {
 public:
  using ReadImage = std::function<cv::Mat(const std::string& name)>;  // grey; empty when unreadable
  BoardSearchInBackground(std::vector<std::string> names, ReadImage read, cv::Size inner_corners, int threads);
  ~BoardSearchInBackground();
  BoardSearchInBackground(const BoardSearchInBackground&) = delete;
  BoardSearchInBackground& operator=(const BoardSearchInBackground&) = delete;

  // The sightings in the map's keyframes (by Keyframe::name), as FindBoard gives them. The
  // calling thread searches too while it waits, at its own priority: the images not yet
  // started, then those an idle thread still holds, so that a busy machine cannot starve the
  // result. A keyframe whose name was not given is searched here. `progress(done, total)`.
  // Once: the background threads stop when it returns.
  std::vector<BoardSighting> Sightings(const map::Map& map, const std::function<void(int, int)>& progress = {},
                                       const CancellationToken& cancel = {});

  struct State;  // shared with the threads

 private:
  std::shared_ptr<State> state_;
};

// The corners triangulated from the keyframes' poses: each sighting put in the first one's corner
// order (a chessboard is found starting from any of its corners), then every corner triangulated
// from all sightings, and sightings that disagree (a wrong detection) dropped. Throws
// map::MapError, saying what to try, when fewer than two sightings agree or they see the board
// from nearly the same direction (under 3°).
TriangulatedBoard TriangulateBoard(const map::Map& map, const std::vector<BoardSighting>& sightings,
                                   cv::Size inner_corners);

// The similarity from the map's current frame into the metric one, and the frame record.
struct MetricFit {
  Sim3 to_metric;
  map::MapFrame frame;  // scale source, z_up, scale error, how
  double fit_rms_m = 0; // board: the corners' distance to the true grid after the fit, metres
};

// Throws map::MapError when the triangulated corners do not form the board's grid (another board
// size, a wrong detection): their fit residual above a fifth of a square.
MetricFit FitFromBoard(const map::Map& map, const TriangulatedBoard& board, const BoardSpec& spec);

// One end of a known distance: the same scene point's pixel in a keyframe.
struct PointSighting {
  std::string keyframe_name;  // as Map::keyframes[].name, or its file name alone
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

struct TriangulatedPoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  double uncertainty = 0;  // map units: the position's error for a one-pixel error in the pixels
};

// Throws map::MapError naming an unknown keyframe, fewer than two sightings, a keyframe given
// twice, rays less than 3 degrees apart (nearly one ray: the point could be anywhere along it),
// or rays that do not meet (more than 4 px apart when reprojected).
TriangulatedPoint TriangulatePoint(const map::Map& map, const std::vector<PointSighting>& sightings);

// Scale from the distance between two triangulated points; up and origin from the floor.
MetricFit FitFromDistance(const map::Map& map, const TriangulatedPoint& a, const TriangulatedPoint& b, double metres);

// People film a room holding a phone or webcam at 1.2–1.7 m; 1.45 m is the middle of that range,
// and ±0.25 m its likely error (17 %), which the estimate states.
inline constexpr double kTypicalCameraHeight = 1.45;
inline constexpr double kCameraHeightRelativeError = 0.17;

// The floor's estimate: the floor the lowest dense plane of the points, the cameras' median height
// over it kTypicalCameraHeight. Its scale_error is kCameraHeightRelativeError, or half the 10-90 %
// range of the cameras' own heights over the floor where that is wider (its `how` then says
// "doubtful"). Throws map::MapError when the points hold no floor below the cameras, or the floor
// found cannot be trusted (more than 1 % of the points below it, the cameras' heights over it
// varying by more than +-35 %): the scale could then be off by any factor.
MetricFit FitFromCameraHeight(const map::Map& map);

// The keyframes' poses and the points moved into the metric frame, and map->frame set from the
// fit (its from_colmap composed with the map's previous one).
void ApplyMetricFit(const MetricFit& fit, map::Map* map);

// (a ∘ b)(x) = a(b(x)).
Sim3 Compose(const Sim3& a, const Sim3& b);

}  // namespace arview::mapping
