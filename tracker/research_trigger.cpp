#include "tracker/research_trigger.h"

#include <array>

namespace arview::tracker {

void ResearchTriggerOptions::Check(const OptionNames& names) const {
  RequireOption(occlusion_credit_frames >= 0, names("occlusion_credit_frames"), "0 (off) or more", occlusion_credit_frames);
  RequireOption(min_followed_share >= 0 && min_followed_share <= 1, names("min_followed_share"), "in [0, 1]",
                min_followed_share);
  RequireOption(min_quadrants >= 0 && min_quadrants <= 4, names("min_quadrants"), "in 0..4", min_quadrants);
  RequireOption(min_quadrant_tracks >= 1, names("min_quadrant_tracks"), "at least 1", min_quadrant_tracks);
  RequireOption(max_frames_between >= 0, names("max_frames_between"), "0 (never) or more", max_frames_between);
}

void ResearchTrigger::Occluded(std::uint32_t frame, int tracks) {
  if (options_.occlusion_credit_frames == 0 || tracks <= 0) return;
  occluded_.push_back({frame, tracks});
  while (!occluded_.empty() &&
         frame - occluded_.front().frame >= static_cast<std::uint32_t>(options_.occlusion_credit_frames))
    occluded_.pop_front();
}

int ResearchTrigger::Credit(std::uint32_t frame) const {
  int credit = 0;
  for (const Drops& d : occluded_)
    if (frame - d.frame < static_cast<std::uint32_t>(options_.occlusion_credit_frames)) credit += d.tracks;
  return credit;
}

bool ResearchTrigger::Due(std::uint32_t frame, std::span<const Eigen::Vector2d> followed, cv::Size size) const {
  if (AgeDue(frame)) return true;
  const int n = static_cast<int>(followed.size());
  if (n >= replenish_below_) return false;
  if (options_.occlusion_credit_frames == 0) return true;
  if (n < options_.min_followed_share * replenish_below_ || n + Credit(frame) < replenish_below_) return true;
  std::array<int, 4> per_quadrant{};
  for (const Eigen::Vector2d& px : followed)
    ++per_quadrant[(px.x() >= size.width / 2.0 ? 1 : 0) + (px.y() >= size.height / 2.0 ? 2 : 0)];
  int quadrants = 0;
  for (const int count : per_quadrant) quadrants += count >= options_.min_quadrant_tracks;
  return quadrants < options_.min_quadrants;
}

}  // namespace arview::tracker
