#pragma once
// Matches on things that move in front of the map (people walking through, a door swinging):
// rejected before the pose is fitted, so that they are never averaged into it. Two tests on the
// flow tracks, one on guided matching's matches:
//   - a track whose LK patch error is many times its own in the frame before (and the frame's
//     median): its patch changed (a person stepped over the point, or the point went behind
//     one), so where LK put it is not the point's; a global light change scales every track's
//     error alike and passes;
//   - a track that moved against the pose's prediction by more than the frame's tracks did, in
//     `streak_frames` consecutive frames: a static point's flow agrees with the prediction up to
//     an error all tracks share (the prediction's), a point carried by a moving object does not;
//   - a guided match within `region_px` of a track rejected this frame: the part of the image a
//     mover covers, whose keypoints are not the map's static structure.
// The filter keeps, per map point, the streak of frames its track disagreed; a point not
// followed in the previous frame starts again from none.

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

#include "base/option_check.h"

namespace arview::tracker {

struct MovingTrackOptions {
  bool enabled = true;
  // The LK error (mean absolute patch difference) over the larger of the track's own in the
  // frame before and the frame's median beyond which a track's patch has changed.
  double patch_error_ratio = 4.0;
  // A track disagrees with the prediction when its flow, less the frame's median disagreement
  // (the prediction's own error), is off by more than max(min_px, scale x the tracks' median
  // absolute deviation).
  double against_prediction_min_px = 1.5;
  double against_prediction_scale = 4.0;
  int streak_frames = 2;  // consecutive disagreeing frames before a track is dropped
  double region_px = 16;  // guided matches this near a rejected track's pixel are dropped

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

// One frame's flow tracks as the filter reads them.
struct FlowTracks {
  std::span<const std::uint32_t> point_ids;
  std::span<const Eigen::Vector2d> pixels;     // where LK put them
  std::span<const Eigen::Vector2d> predicted;  // where the predicted pose projects their points
  std::span<const float> lk_errors;            // LK's patch error per track
};

struct MovingTrackVerdict {
  std::vector<bool> keep;                  // per track
  std::vector<Eigen::Vector2d> rejected;   // the rejected tracks' pixels
  int by_patch = 0;                        // rejected for a changed patch
  int by_motion = 0;                       // rejected for moving against the prediction
};

class MovingTrackFilter {
 public:
  MovingTrackFilter(const MovingTrackOptions& options, std::size_t map_points);
  // Judges one frame's tracks (frame numbers increase by one a tracked frame) and updates the
  // streaks. No allocation beyond the verdict's vectors.
  MovingTrackVerdict Judge(const FlowTracks& tracks, std::uint32_t frame);
  // Whether a guided match at `pixel` lies where a track was rejected this frame.
  static bool NearRejected(const MovingTrackVerdict& verdict, const Eigen::Vector2d& pixel, double region_px);
  const MovingTrackOptions& options() const { return options_; }

 private:
  struct Streak {
    std::uint32_t frame = 0;  // the frame it was last judged in
    std::uint8_t count = 0;   // consecutive frames the track disagreed, up to that frame
    float error = 0;          // its LK patch error in that frame
  };
  MovingTrackOptions options_;
  std::vector<Streak> streaks_;  // per map point
  std::vector<float> scratch_;   // medians' working copies
};

}  // namespace arview::tracker
