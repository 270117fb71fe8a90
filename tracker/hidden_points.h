#pragma once
// Map points whose flow track was lost while they were in view: someone walking through stepped
// in front of them (LK lost the patch, or the moving-track filter rejected it). Each is kept with
// the last frame that saw it (that frame's flow pyramid and the point's pixel in it), so that when
// the mover has passed it is followed back by LK from there, where the pose puts it, instead of
// the frame re-searching the map with SIFT (guided matching) for tracks the walker took away.
// A point is kept for `max_age_frames` tracked frames at most: the older the frame, the more the
// view has changed since, and the less exactly LK finds the point again.

#include <opencv2/core.hpp>

#include <cstdint>
#include <deque>
#include <vector>

#include "base/option_check.h"

namespace arview::tracker {

struct HiddenPointOptions {
  // Off by default: with two walkers on the demo's lap they took 9 re-search frames of 72 off
  // and cost the worst frames (two over 5 px; docs/tracker.md, "Second round").
  bool enabled = false;
  int max_age_frames = 60;  // tracked frames a lost point is kept for (2 s at 30 fps)
  // A point followed back is taken when LK ends within this many working pixels of where the
  // pose of the frame's flow tracks projects it, with a patch error within the moving-track
  // filter's bound (MovingTrackOptions::patch_error_ratio times the flow's median).
  double radius_px = 2.0;

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

class HiddenPoints {
 public:
  // The points lost after one frame, with that frame's pyramid and their pixels in it.
  struct Batch {
    std::int64_t frame = 0;  // the tracker's frame number of the frame that last saw them
    std::vector<cv::Mat> pyramid;
    std::vector<cv::Point2f> pixels;
    std::vector<std::uint32_t> point_ids;
  };

  // Keeps a batch (an empty one is ignored).
  void Add(Batch batch);
  // Forgets the batches of frames more than `max_age_frames` before `frame`.
  void Expire(std::int64_t frame, int max_age_frames);
  // Forgets, in every batch, the points `found(point_id)` says are tracked again.
  template <typename Found>
  void Remove(const Found& found);
  void Clear() { batches_.clear(); }
  std::size_t size() const;  // points kept, over all batches
  const std::deque<Batch>& batches() const { return batches_; }

 private:
  std::deque<Batch> batches_;  // oldest first
};

template <typename Found>
void HiddenPoints::Remove(const Found& found) {
  for (Batch& batch : batches_) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < batch.point_ids.size(); ++i) {
      if (found(batch.point_ids[i])) continue;
      batch.pixels[kept] = batch.pixels[i];
      batch.point_ids[kept] = batch.point_ids[i];
      ++kept;
    }
    batch.pixels.resize(kept);
    batch.point_ids.resize(kept);
  }
  std::erase_if(batches_, [](const Batch& b) { return b.point_ids.empty(); });
}

}  // namespace arview::tracker
