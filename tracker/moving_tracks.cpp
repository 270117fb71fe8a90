#include "tracker/moving_tracks.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arview::tracker {
namespace {

float Median(std::vector<float>& values) {
  if (values.empty()) return 0.f;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void MovingTrackOptions::Check(const OptionNames& names) const {
  RequireOption(patch_error_ratio > 1, names("patch_error_ratio"), "above 1", patch_error_ratio);
  RequireOption(against_prediction_min_px > 0, names("against_prediction_min_px"), "above 0", against_prediction_min_px);
  RequireOption(against_prediction_scale > 0, names("against_prediction_scale"), "above 0", against_prediction_scale);
  RequireOption(streak_frames >= 1 && streak_frames <= 255, names("streak_frames"), "in 1..255", streak_frames);
  RequireOption(region_px >= 0, names("region_px"), "0 or more", region_px);
}

MovingTrackFilter::MovingTrackFilter(const MovingTrackOptions& options, std::size_t map_points)
    : options_(options), streaks_(map_points) {}

MovingTrackVerdict MovingTrackFilter::Judge(const FlowTracks& tracks, std::uint32_t frame) {
  const std::size_t n = tracks.pixels.size();
  MovingTrackVerdict verdict;
  verdict.keep.assign(n, true);
  if (!options_.enabled || n == 0) return verdict;

  // The prediction's own error, shared by every track: the median disagreement, per axis.
  Eigen::Vector2d shared = Eigen::Vector2d::Zero();
  for (int axis = 0; axis < 2; ++axis) {
    scratch_.clear();
    for (std::size_t i = 0; i < n; ++i) scratch_.push_back(static_cast<float>(tracks.pixels[i][axis] - tracks.predicted[i][axis]));
    shared[axis] = Median(scratch_);
  }
  scratch_.clear();
  for (std::size_t i = 0; i < n; ++i) scratch_.push_back(static_cast<float>((tracks.pixels[i] - tracks.predicted[i] - shared).norm()));
  const double bound = std::max(options_.against_prediction_min_px, options_.against_prediction_scale * Median(scratch_));
  scratch_.assign(tracks.lk_errors.begin(), tracks.lk_errors.end());
  const float median_error = std::max(Median(scratch_), std::numeric_limits<float>::min());

  for (std::size_t i = 0; i < n; ++i) {
    Streak& streak = streaks_[tracks.point_ids[i]];
    // Judged in the frame before this one (frame 0 is "never": the tracker counts from 1).
    const bool followed_before = streak.frame != 0 && streak.frame + 1 == frame;
    if (!followed_before) streak.count = 0;
    streak.frame = frame;
    const bool disagrees = (tracks.pixels[i] - tracks.predicted[i] - shared).norm() > bound;
    streak.count = disagrees ? static_cast<std::uint8_t>(std::min(streak.count + 1, 255)) : 0;
    // A patch's LK error grows with its contrast: a sharp corner's is several times the frame's
    // median on every frame (with two walkers on the demo's lap, a bound on the median alone
    // dropped 10-45 tracks of ~250 a frame, most of them on the static room, and the tracks ran
    // out every 10-15 frames). So a track's error is compared with its own in the frame before;
    // a track followed for the first time is judged by its motion alone.
    const bool changed_patch =
        followed_before && tracks.lk_errors[i] > options_.patch_error_ratio * std::max(streak.error, median_error);
    streak.error = tracks.lk_errors[i];
    const bool moving = streak.count >= options_.streak_frames;
    if (!changed_patch && !moving) continue;
    verdict.keep[i] = false;
    verdict.rejected.push_back(tracks.pixels[i]);
    ++(changed_patch ? verdict.by_patch : verdict.by_motion);
  }
  return verdict;
}

bool MovingTrackFilter::NearRejected(const MovingTrackVerdict& verdict, const Eigen::Vector2d& pixel, double region_px) {
  const double r2 = region_px * region_px;
  return std::any_of(verdict.rejected.begin(), verdict.rejected.end(),
                     [&](const Eigen::Vector2d& p) { return (p - pixel).squaredNorm() <= r2; });
}

}  // namespace arview::tracker
