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
// - the camera rotations against each pair's own two-view geometry: COLMAP's database keeps, for
//   every matched pair of frames, the essential matrix estimated from that pair's matches alone.
//   Its rotation agrees with the map's relative rotation within a degree or two for a
//   well-matched pair; a part of the path that COLMAP registered wrongly (a fold: on phone-fox a
//   default map once put frames 0-8 at rotations 10-35 degrees off, all else right, with a
//   normal reprojection error) disagrees with most of its pairs. A milder fold (frames 0-8 off by
//   3-10 degrees, keyframe centres off by up to 0.5 of the path's width) disagrees by less than
//   the 10 degrees that count a pair as disagreeing, so each keyframe is also judged by the
//   median disagreement of its own pairs against the map's typical one: on 1080x1920 phone frames
//   a right map's keyframes stay within 1 degree (the essential matrices are that precise), the
//   folded ones are 3-10 degrees off; on 640x480 renders a right map's keyframes reach 2.8 degrees
//   where its median pair is at 0.9 (docs/mapping.md, "The map's self-check"). A pair whose own
//   matches the map's relative pose fits as well as its essential matrix does counts as agreeing
//   whatever that matrix's rotation: where the matches hold the rotation loosely (a wall filmed
//   walking towards it) COLMAP's minimal-sample essential matrix can be degrees off a right map.
// The verdict is a list of warnings, each saying what it saw and what to do, each read after "the
// map " (`arview map` and `map info` print "warning: the map explains only 3% ..."); the map is
// still written (a warning, not a refusal: docs/mapping.md, "The map's self-check").

#include <Eigen/Core>

#include <array>
#include <cstdint>
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
  // Above this, the points sit next to the cameras: a collapsed model (the rendered venue's room
  // of 175 frames alone, sequential matching: 1.5e11, keyframes 39-55 degrees off; a walk down a
  // corridor is tens).
  double max_extent_ratio = 1000;
  double min_triangulation_deg = 2.0;  // median over points
  int two_view_min_inliers = 300;        // pairs matched at least this well are compared
  double two_view_max_disagreement_deg = 10.0;
  double max_disagreeing_fraction = 0.15;   // more of the compared pairs disagreeing: a fold
  // ... and at least this many of them: on a small map one pair's minimal-sample essential matrix
  // off by over 10 degrees is over the fraction alone (1 of 5 pairs: 20%; a right 6-frame
  // templeRing map, docs/mapping.md "A milder fold").
  int min_disagreeing_pairs = 2;
  // A keyframe is "off" when the median disagreement of its pairs (at least
  // keyframe_min_pairs of them) exceeds keyframe_off_factor x the median over all the map's
  // pairs, clamped to [keyframe_min_off_deg, two_view_max_disagreement_deg]. Two neighbouring
  // keyframes off make a fold: a fold is a stretch of the path, while the imprecise essential
  // matrices of small frames put single keyframes here and there over the limit. The factor:
  // COLMAP keeps the essential matrix of its best minimal sample, and on right templeRing maps
  // (640x480, median pair 0.6 degrees) two neighbouring keyframes' pairs reached 6.8 and 7.9
  // degrees (11-13x; a factor of 5 refused three of three maps built with arview's matcher),
  // while phone-fox's folded keyframes sat at 3-10 degrees against a median pair of 0.16-0.3
  // (19x and more). docs/mapping.md, "A milder fold".
  int keyframe_min_pairs = 3;
  double keyframe_off_factor = 15.0;
  double keyframe_min_off_deg = 2.0;
  // A pair whose verified matches the map's own relative pose fits (median Sampson distance, in
  // pixels) within this, or within its essential matrix's own fit, is no evidence of a fold,
  // whatever angle its essential matrix makes with the map: COLMAP keeps the essential matrix of
  // its best minimal sample, and where the matches hold the rotation loosely (a wall filmed
  // walking towards it: the rendered venue's right map had pairs 2-8 degrees off that its poses
  // fitted at 0.03-0.16 px, and 3.2 px and more once a keyframe was turned 4 degrees; docs/mapping.md,
  // "The map's self-check") that one can be degrees from a pose that fits them better.
  double two_view_fit_px = 0.5;
};

// COLMAP's two-view geometry of two keyframes: the essential matrix of their matches alone.
struct TwoViewGeometry {
  int keyframe_a = 0, keyframe_b = 0;  // indices into Map::keyframes
  int inliers = 0;                     // verified matches
  Eigen::Matrix3d essential = Eigen::Matrix3d::Zero();  // x_b^T E x_a = 0, normalised coordinates
  // The verified matches: each a keypoint index of keyframe a and one of keyframe b (into
  // CheckMap's `keypoints`). Empty when not known: then only the rotations are compared.
  std::vector<std::array<std::uint32_t, 2>> matches;
};

// How far, in degrees, `rotation_ab` (camera a to camera b: R_b R_a^T of world-to-camera
// rotations) is from the rotation `essential` implies: of the two it admits, the nearer (the
// other is the first turned by 180 degrees about the baseline). The whole rotation is compared,
// not only its angle: a fold turns frames about another axis than the path does. A zero or
// rank-one matrix gives nothing.
std::optional<double> RotationDisagreementDeg(const Eigen::Matrix3d& essential, const Eigen::Matrix3d& rotation_ab);

// The essential matrix of the motion from camera a to camera b (world-to-camera poses):
// x_b^T E x_a = 0 with E = [t]x R, R = R_b R_a^T, t = t_b - R t_a.
Eigen::Matrix3d EssentialBetween(const calib::Pose& a, const calib::Pose& b);

struct MapCheck {
  int keyframes = 0;
  double explained_fraction = 0;     // median over keyframes: observations / keypoints
  double path_extent = 0;            // largest distance between two keyframe centres (map units)
  double scene_depth = 0;            // median over keyframes of the median depth of their points
  double extent_ratio = 0;           // path_extent / scene_depth
  double median_triangulation_deg = 0;
  int moving_pairs = 0;              // consecutive keyframe pairs whose points move >= moving_pair_px
  double still_fraction = 0;         // median over those pairs
  int two_view_pairs = 0;            // keyframe pairs compared with their two-view geometry
  double disagreeing_fraction = 0;      // the fraction of those whose rotations disagree
  double median_disagreement_deg = 0;   // over the compared pairs
  double keyframe_off_deg = 0;          // the limit a keyframe's own median was held to
  int fitted_pairs = 0;  // compared pairs whose matches the map's own poses fit (two_view_fit_px): never off
  std::vector<int> disagreeing_frames;  // frame indices of the keyframes that are off (MapCheckLimits)
  int off_neighbours = 0;               // consecutive keyframe pairs both off
  // Per keyframe (Map::keyframes order): how many of its compared pairs agree within
  // keyframe_off_deg (0 without compared pairs), for KeyframeToStartFrom. Not in check.json.
  std::vector<int> keyframe_agreeing_pairs;
  std::vector<std::string> warnings;
  bool flagged() const { return !warnings.empty(); }
};

// Whether `check` found a fold: its rotations disagree with the two-view geometry in more of the
// compared pairs than `limits` allow (a fraction, and a count), or two neighbouring keyframes are off.
bool Folded(const MapCheck& check, const MapCheckLimits& limits = {});

// The keyframe (index into map.keyframes) a new mapper run should start from when `check` found a
// fold: one that is not off, not in `excluded` (COLMAP image ids of earlier starts), with the
// most pairs agreeing with the map; among equals, the one furthest (in keyframes) from an off one.
// Nothing when no keyframe qualifies (no two-view comparison).
std::optional<int> KeyframeToStartFrom(const map::Map& map, const MapCheck& check,
                                       const std::vector<std::uint32_t>& excluded);

// `keypoints[k]`: every keypoint COLMAP found in keyframe k (OpenCV pixels), observations or not.
// `two_view`: the keyframes' two-view geometries (mapping/colmap_model.h); none: not compared.
MapCheck CheckMap(const map::Map& map, const std::vector<std::vector<Eigen::Vector2f>>& keypoints,
                  const std::vector<TwoViewGeometry>& two_view = {}, const MapCheckLimits& limits = {});

// The check beside the map (check.json in the map folder): written by `arview map`, printed by
// `arview map info`. ReadMapCheck: nothing when the file is absent (a map from before the check);
// MapError when it is there but unreadable.
inline constexpr const char* kMapCheckFileName = "check.json";
void WriteMapCheck(const MapCheck& check, const std::filesystem::path& file);
std::optional<MapCheck> ReadMapCheck(const std::filesystem::path& file);

// A fraction as the check's messages write it: "28%", "5.8%".
std::string Percent(double fraction);
// A number with `digits` decimals, as the check's messages write it: "3.2".
std::string Fixed(double value, int digits);
// The off frames of a check for a message: "2, 4, 8", the first 12 and ", ..." after them.
std::string OffFrameList(const MapCheck& check);

// One line of figures ("explains 34% of the features, ...").
std::string DescribeMapCheck(const MapCheck& check);

}  // namespace arview::mapping
