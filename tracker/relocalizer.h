#pragma once
// Relocalization without a prior: SIFT on the frame, k-nearest-neighbour search over the map's
// descriptors with a ratio test between distinct map points, then the pose solver.

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "map/descriptor_index.h"
#include "map/map.h"
#include "tracker/absolute_pose.h"
#include "tracker/features.h"
#include "tracker/working_resolution.h"

namespace arview::tracker {

struct MatchOptions {
  // Lowe's ratio: best distance / best distance to a different map point. A map point owns one
  // descriptor per observation, so the second neighbour is often the same point; k neighbours
  // are fetched to find the nearest other point.
  double ratio = 0.8;
  int knn = 4;

  // Throws OptionError naming the first bad field (base/option_check.h; tracker/tracker_options.cpp).
  void Check(const OptionNames& names = {}) const;
};

// A frame keypoint matched to a map point.
struct MapMatch {
  int keypoint = 0;
  std::uint32_t point = 0;
  float distance = 0;
};

// The `count` keyframes that observe most of `points` (map point indices), most first, ties by
// index; keyframes that observe none are left out.
std::vector<int> KeyframesSeeingMost(const map::Map& map, const std::vector<std::uint32_t>& points, int count);

// Global matching; each map point keeps only its closest keypoint.
std::vector<MapMatch> MatchToMap(const Features& features, const map::Map& map,
                                 const map::DescriptorIndex& index, const MatchOptions& options);

// The frame's keypoints matched to each of `keyframes` (indices into map.keyframes) on its own,
// as two photos are matched: a keypoint's nearest row of that keyframe passes when it is nearer
// than `ratio` times the keyframe's second nearest row, and gives the row's map point. The rows
// come from the map's index, `knn` nearest a keypoint: a keyframe with one row among them has its
// second beyond the last (its distance bounds the second). A keypoint may match in several
// keyframes, to the same point or not.
std::vector<MapMatch> MatchToKeyframes(const Features& features, const map::Map& map,
                                       const map::DescriptorIndex& index, const std::vector<int>& keyframes,
                                       int knn, double ratio);

// The correspondences of a localisation, kept for the next frame's optical flow.
struct Track2D3D {
  std::vector<cv::Point2f> pixels;
  std::vector<std::uint32_t> points;
};

// AbsolutePoseOptions with relocalization's RANSAC threshold and refinement (RelocalizerOptions::pose).
inline AbsolutePoseOptions RelocalizationPoseOptions() {
  AbsolutePoseOptions options;
  options.ransac_threshold_px = 2.0;
  // The Cauchy loss bends at 1 px, as in COLMAP's image registration: a relocalised pose has no
  // flow behind it, and on still photos (Herz-Jesus-P25, three maps) the median centre error
  // fell 9.12 -> 8.51 mm against 2 px, phone-fox's and templeRing's too (docs/tracker.md,
  // "Herz-Jesus-P25"). Tracked frames keep TrackingOptions::refine_loss_scale_px.
  options.refinement.loss_scale_px = 1.0;
  return options;
}

struct RelocalizerOptions {
  // Relocalization's own SIFT, in two regimes by whether sift_long_side reduces the tracker's
  // working frame.
  // At the frame's own size (640x480: templeRing, the demo's room) it runs on frames without a
  // prior pose: every frame of a set of photos, the first of a video and those after a loss.
  // There its precision is the pose's, and COLMAP's contrast threshold (0.02: the weak structure
  // the map's features hold) with up to 2000 keypoints places the frames closer: templeRing's
  // odd frames over six fresh default maps, centre error median of the maps 0.926 -> 0.877 mm,
  // RMSE lower on all six. The tracker's wide search (it has a prior) extracts guided matching's
  // SIFT instead, and flow does not follow the weak keypoints (Tracker): only so did the
  // rendered room's blurred lap keep its median error (4.19 -> 4.22 mm over 8 start frames, RMSE
  // +10 %; docs/tracker.md, "COLMAP's threshold without a prior").
  FeatureOptions features = {.max_features = 2000, .contrast_threshold = 0.02};
  // On a reduced frame (a 1080p phone) relocalization is the fallback that must be quick, and the
  // flow and guided matching that follow restore the precision: OpenCV's threshold and 1000
  // keypoints, and guided matching's features (TrackingOptions) are matched globally through
  // their strongest max_features. At COLMAP's threshold phone-fox's relocalizations cost ~1.4x
  // (more extrema to refine and describe, and to search the map for).
  FeatureOptions reduced_features = {.max_features = 1000, .contrast_threshold = 0.04};
  int sift_long_side = 640;
  // Working frames up to this longest side are given to SIFT at their own size, with `features`,
  // however short sift_long_side is (0: none). A still photo is posed by its relocalization
  // alone, so its SIFT's scale is the pose's precision: Herz-Jesus-P25's 768x512 photos came
  // 1.4x closer to COLMAP's registration at their own size than reduced to 640 and relocalised
  // at 480 (docs/tracker.md, "Herz-Jesus-P25"). 768 leaves phone-fox's 540x960 and every frame
  // the working resolution reduces to 960 as they were.
  int sift_own_size_up_to = 768;
  // Relocalization's own SIFT (a frame on which guided matching extracted nothing: the first of
  // a session, or after tracking was lost) on a smaller image still, this longest side, when the
  // working frame is longer than `sift_long_side` (0: as sift_long_side). Relocalization has to
  // find the pose, not refine it: the flow and guided matching that follow work at full
  // precision. On phone-fox (1080x1920, working 540x960) SIFT at 480 costs ~0.6x of 640, the same
  // frames localise, the clip's centre error is unchanged. Frames SIFT sees at their own size
  // (640x480 and smaller) are not reduced: there every frame of a wide-baseline set is a
  // relocalization and its precision is the pose's (templeRing: 0.946 → 1.024 mm at 480).
  int reloc_sift_long_side = 480;
  MatchOptions matching;
  // Relocalization's second look, the way COLMAP's registration finds a photo's correspondences:
  // once posed, the frame is matched to each of this many keyframes, those that see most of the
  // pose's inliers, with the ratio test among that keyframe's own keypoints, and posed again on
  // those matches and the global ones (0: off). The global ratio test is between every map
  // point: a façade's repeated ornament, or one point COLMAP split into two tracks, fails it
  // where one photo holds it once. Over the odd frames of Herz-Jesus-P25 (3 maps), templeRing (4)
  // and phone-fox (4), the pooled centre error's mean 7.74 -> 7.54 mm, 0.985 -> 0.966 mm and
  // 0.00247 -> 0.00235 units, phone-fox's inliers +23-26 % (docs/tracker.md, "Seventh round").
  int keyframe_matching = 5;
  // Index neighbours of a keypoint looked among for a keyframe's nearest two rows (MatchToKeyframes).
  int keyframe_knn = 16;
  // RANSAC's inlier threshold 2 px: the pose is refined on RANSAC's inliers, and the map points
  // 2-4 px off are the less exactly triangulated. templeRing's odd frames over six fresh default
  // maps: centre error median of the maps 0.877 -> 0.823 mm (5 of 6 maps under 0.9 mm, 3 at
  // 4 px); the room's blurred lap at 640x480 over 8 start frames: median 4.22 -> 4.20 mm, RMSE
  // 6.19 -> 6.16 mm; at 1920x1080 over 3 start frames 6.65 -> 6.49 mm; phone-fox unchanged
  // (docs/tracker.md, "RANSAC at 2 px when relocalising"). Tracking's RANSAC
  // keeps its own threshold (TrackingOptions::ransac_threshold_px).
  AbsolutePoseOptions pose = RelocalizationPoseOptions();

  // Throws OptionError naming the first bad field (base/option_check.h; tracker/tracker_options.cpp).
  void Check(const OptionNames& names = {}) const;
};

struct RelocalizationResult {
  AbsolutePoseResult pose;  // ok / failure / reason / stats of the solver
  int keypoints = 0;
  int matches = 0;
  double extract_ms = 0;
  double match_ms = 0;
  Track2D3D inliers;  // the verified correspondences (empty unless pose.ok)
};

class Relocalizer {
 public:
  // `map` and `index` must outlive the relocalizer. `camera`: the camera of the images it is
  // given (the map camera, or the map camera scaled to the tracker's working resolution).
  Relocalizer(const map::Map& map, const calib::Camera& camera, const map::DescriptorIndex& index,
              const RelocalizerOptions& options);
  RelocalizationResult Relocalize(const cv::Mat& gray) const;
  // SIFT of `gray` (the camera's size) by `extractor` on the image reduced to SiftLongSide,
  // keypoints in `gray`'s pixels. Another size is given to SIFT as it is.
  Features Extract(const cv::Mat& gray, const SiftExtractor& extractor) const {
    return ExtractAt(gray, extractor, sift_resolution_);
  }
  // The features Relocalize(gray) extracts: its own extractor on the image reduced to
  // reloc_sift_long_side.
  Features ExtractOwn(const cv::Mat& gray) const { return ExtractAt(gray, extractor_, reloc_resolution_); }
  // Whether ExtractOwn sees a smaller image than Extract (a reduced frame: phone-fox's 1080x1920).
  bool OwnExtractionSmaller() const {
    return reloc_resolution_.work().width < sift_resolution_.work().width;
  }
  // Features already extracted (e.g. by guided matching of the same frame).
  RelocalizationResult Relocalize(const Features& features) const;
  const RelocalizerOptions& options() const { return options_; }
  const SiftExtractor& extractor() const { return extractor_; }

 private:
  const map::Map& map_;
  calib::Camera camera_;
  const map::DescriptorIndex& index_;
  RelocalizerOptions options_;
  Features ExtractAt(const cv::Mat& gray, const SiftExtractor& extractor,
                     const WorkingResolution& resolution) const;

  // `result` (posed on `global`, the matches of `features`) posed again on those and the matches
  // to the keyframes that see most of its inliers (RelocalizerOptions::keyframe_matching); kept
  // as it is when that pose fails.
  void MatchKeyframesAndPose(const Features& features, const std::vector<MapMatch>& global,
                             RelocalizationResult* result) const;

  SiftExtractor extractor_;
  WorkingResolution sift_resolution_;   // the given image → the image SIFT runs on (reduced():
                                        // reduced_features apply)
  WorkingResolution reloc_resolution_;  // the same for relocalization's own extraction
};

// The longest side of the image SIFT runs on for frames of `camera` (sift_long_side, or 0: the
// frame as it is, when it is no longer than sift_own_size_up_to).
int SiftLongSide(const calib::Camera& camera, const RelocalizerOptions& options);

// The SIFT options for frames of `camera`: options.reduced_features when SiftLongSide reduces
// them, else options.features.
const FeatureOptions& ActiveFeatures(const calib::Camera& camera, const RelocalizerOptions& options);

// The longest side of relocalization's own SIFT image for frames of `camera` (see
// RelocalizerOptions::reloc_sift_long_side); 0: the frame as it is.
int RelocSiftLongSide(const calib::Camera& camera, const RelocalizerOptions& options);

// The `max_count` keypoints of `features` with the strongest response (all of them when there are
// no more), in their original order.
Features StrongestFeatures(const Features& features, int max_count);

// Pixels and world points of `matches`, in order, for the pose solver.
void GatherCorrespondences(const Features& features, const map::Map& map,
                           const std::vector<MapMatch>& matches,
                           std::vector<Eigen::Vector2d>* pixels,
                           std::vector<Eigen::Vector3d>* points);

}  // namespace arview::tracker
