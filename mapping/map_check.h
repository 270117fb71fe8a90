#pragma once
// What `arview map` checks in the map it built (issue 17, "a map that cannot be right is
// refused or flagged").
//
// COLMAP reconstructs whatever moves rigidly in front of the camera. Filmed by a camera that
// never moves, an object moved by hand becomes a complete-looking map whose camera path never
// happened; a camera that only turned gives a map without depth. Neither shows in the
// registration count or the reprojection error, so the map is looked at as a whole:
// - the features that stay still: keypoints of a keyframe that reappear within half a pixel
//   in the next one while the map's own points move by pixels between the two. A still camera
//   filming a moving object leaves the background's features in place; a moving camera moves
//   them all (chance coincidences are a few percent).
// - how much of each frame the map explains: the fraction of a keyframe's keypoints that are
//   observations of map points (the rest is what COLMAP could not fit: moving things, clutter).
// - the camera path's extent against the scene depth: how far apart the keyframes' centres
//   are, relative to the median distance of the points they see.
// - the triangulation angles: per point, the widest angle between two of its rays.
// The verdict is a list of warnings, each saying what it saw and what to do; the map is still
// written (a warning, not a refusal: docs/mapping.md, "The map's self-check").

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "map/map.h"

namespace arview::mapping {

// Thresholds of the warnings (chosen on measured maps, docs/mapping.md).
struct MapCheckLimits {
  double still_radius_px = 0.5;        // a keypoint "stays" when one of the next keyframe is this close
  double moving_pair_px = 2.0;         // a pair counts when the map's points move this much (median)
  double max_still_fraction = 0.10;    // more still features than this: a still camera, a moving object
  double min_explained_fraction = 0.05;
  double min_extent_ratio = 0.05;      // path extent / scene depth
  double min_triangulation_deg = 2.0;  // median over points
};

struct MapCheck {
  int keyframes = 0;
  double explained_fraction = 0;     // median over keyframes: observations / keypoints
  double path_extent = 0;            // largest distance between two keyframe centres (map units)
  double scene_depth = 0;            // median over keyframes of the median depth of their points
  double extent_ratio = 0;           // path_extent / scene_depth
  double median_triangulation_deg = 0;
  int moving_pairs = 0;              // consecutive keyframe pairs whose points move >= moving_pair_px
  double still_fraction = 0;         // median over those pairs
  std::vector<std::string> warnings;
  bool flagged() const { return !warnings.empty(); }
};

// `keypoints[k]`: every keypoint COLMAP found in keyframe k (OpenCV pixels), observations or not.
MapCheck CheckMap(const map::Map& map, const std::vector<std::vector<Eigen::Vector2f>>& keypoints,
                  const MapCheckLimits& limits = {});

// The check beside the map (check.json in the map folder): written by `arview map`, printed by
// `arview map info`. ReadMapCheck: nothing when the file is absent (a map from before the check);
// MapError when it is there but unreadable.
inline constexpr const char* kMapCheckFileName = "check.json";
void WriteMapCheck(const MapCheck& check, const std::filesystem::path& file);
std::optional<MapCheck> ReadMapCheck(const std::filesystem::path& file);

// One line of figures ("explains 34% of the features, ...").
std::string DescribeMapCheck(const MapCheck& check);

}  // namespace arview::mapping
