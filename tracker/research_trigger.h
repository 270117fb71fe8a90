#pragma once
// When a tracked frame re-searches the map with SIFT (guided matching) for more tracks: when the
// flow's tracks fall under `replenish_below`. Someone walking through hides the points under them,
// so their tracks run out three times as fast as on an empty room, and a re-search while the
// walker still covers them finds nothing there (docs/tracker.md, "Third round"). With
// `occlusion_credit_frames` set, the tracks the patch test dropped in that many recent frames
// (their patch changed: something stepped over the point) are counted as expected back, as long
// as the tracks really followed still pin the pose: at least `min_followed_share` of
// `replenish_below`, spread over at least `min_quadrants` of the frame's quadrants.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <deque>
#include <optional>
#include <span>

#include "base/option_check.h"

namespace arview::tracker {

struct ResearchTriggerOptions {
  // Tracked frames a track the patch test dropped counts toward replenish_below; 0: off (a plain
  // count, the default: docs/tracker.md, "Fourth round").
  int occlusion_credit_frames = 0;
  // With credit, the tracks really followed must still be at least this share of replenish_below.
  double min_followed_share = 0.5;
  // ... and lie in at least this many of the frame's four quadrants with min_quadrant_tracks each.
  int min_quadrants = 3;
  int min_quadrant_tracks = 10;
  // Tracked frames after the last re-search after which a frame re-searches whatever its count:
  // flow tracks followed for a while drift together and pull the pose with them (the demo lap's
  // worst 5% of frames, one stretch 54-86 frames after its last re-search: docs/tracker.md,
  // "Fourth round"). Every 10 frames: a better registration on every map of the demo's room
  // tried, for a SIFT extraction every 10 frames ("Sixth round"); 0: never.
  int max_frames_between = 10;

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

class ResearchTrigger {
 public:
  ResearchTrigger(const ResearchTriggerOptions& options, int replenish_below)
      : options_(options), replenish_below_(replenish_below) {}
  // The tracks the patch test dropped in tracked frame `frame` (frames increase).
  void Occluded(std::uint32_t frame, int tracks);
  // Whether frame `frame` is max_frames_between or more after the last re-search (a live session
  // extracts its SIFT ahead for it: Tracker::MaybePrefetch).
  bool AgeDue(std::uint32_t frame) const {
    return options_.max_frames_between > 0 && last_search_ &&
           frame - *last_search_ >= static_cast<std::uint32_t>(options_.max_frames_between);
  }
  // Whether frame `frame`, with `followed` tracks (working pixels) in an image of `size`, re-searches.
  bool Due(std::uint32_t frame, std::span<const Eigen::Vector2d> followed, cv::Size size) const;
  // The tracks counted as expected back in frame `frame`.
  int Credit(std::uint32_t frame) const;
  // Frame `frame` re-searched: earlier drops no longer count (it found what could be found).
  void Searched(std::uint32_t frame) {
    occluded_.clear();
    last_search_ = frame;
  }
  // Forgets everything (the tracker lost its prior).
  void Clear() {
    occluded_.clear();
    last_search_.reset();
  }

 private:
  struct Drops {
    std::uint32_t frame;
    int tracks;
  };
  ResearchTriggerOptions options_;
  int replenish_below_;
  std::deque<Drops> occluded_;  // oldest first, frames with drops only
  std::optional<std::uint32_t> last_search_;  // the frame of the last re-search
};

}  // namespace arview::tracker
