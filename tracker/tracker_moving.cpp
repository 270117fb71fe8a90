// The moving-track filter's steps of Tracker (tracker/moving_tracks.h), apart from tracker.cpp.

#include "tracker/tracker.h"

namespace arview::tracker {
namespace {

// Keeps the correspondences c[i] for i < from and those from `from` on that `keep(i)` accepts, in
// their order; the number removed.
template <typename Keep>
int KeepCorrespondences(std::size_t from, const Keep& keep, std::vector<Eigen::Vector2d>& pixels,
                        std::vector<Eigen::Vector3d>& points, std::vector<std::uint32_t>& ids) {
  std::size_t kept = from;
  for (std::size_t i = from; i < pixels.size(); ++i) {
    if (!keep(i)) continue;
    pixels[kept] = pixels[i];
    points[kept] = points[i];
    ids[kept] = ids[i];
    ++kept;
  }
  const int removed = static_cast<int>(pixels.size() - kept);
  pixels.resize(kept);
  points.resize(kept);
  ids.resize(kept);
  return removed;
}

}  // namespace

MovingTrackVerdict Tracker::DropMovingTracks(const std::vector<Eigen::Vector2d>& predicted, const std::vector<float>& lk_errors,
                                             Correspondences* c, FrameResult* result) {
  const std::size_t n = predicted.size();
  MovingTrackVerdict verdict = moving_filter_.Judge(
      {std::span(c->point_ids).first(n), std::span(c->pixels).first(n), predicted, lk_errors}, static_cast<std::uint32_t>(frames_tracked_));
  result->moving_by_patch = verdict.by_patch;
  result->moving_by_motion = verdict.by_motion;
  result->moving_rejected += KeepCorrespondences(
      0, [&](std::size_t i) { return i >= n || verdict.keep[i]; }, c->pixels, c->points, c->point_ids);
  return verdict;
}

void Tracker::DropClippedTracks(const cv::Mat& gray, std::size_t from, Correspondences* c, FrameResult* result) const {
  if (from >= c->pixels.size()) return;
  const std::vector<bool> clipped = MostlyClipped(gray, std::span(c->pixels).subspan(from),
                                                  options_.tracking.lk_window_px, options_.tracking.clipped);
  result->clipped_rejected += KeepCorrespondences(
      from, [&](std::size_t i) { return !clipped[i - from]; }, c->pixels, c->points, c->point_ids);
}

void Tracker::DropNearMoving(const MovingTrackVerdict& verdict, std::size_t from, Correspondences* c, FrameResult* result) const {
  if (verdict.rejected.empty()) return;
  const double region = options_.tracking.moving.region_px;
  result->moving_rejected += KeepCorrespondences(
      from, [&](std::size_t i) { return !MovingTrackFilter::NearRejected(verdict, c->pixels[i], region); }, c->pixels,
      c->points, c->point_ids);
}

}  // namespace arview::tracker
