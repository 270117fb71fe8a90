#include "tracker/hidden_points.h"

#include <algorithm>

namespace arview::tracker {

void HiddenPointOptions::Check(const OptionNames& names) const {
  RequireOption(max_age_frames >= 1, names("max_age_frames"), "at least 1", max_age_frames);
  RequireOption(radius_px > 0, names("radius_px"), "above 0", radius_px);
}

void HiddenPoints::Add(Batch batch) {
  if (batch.point_ids.empty()) return;
  batches_.push_back(std::move(batch));
}

void HiddenPoints::Expire(std::int64_t frame, int max_age_frames) {
  while (!batches_.empty() && frame - batches_.front().frame > max_age_frames) batches_.pop_front();
}

std::size_t HiddenPoints::size() const {
  std::size_t n = 0;
  for (const Batch& batch : batches_) n += batch.point_ids.size();
  return n;
}

}  // namespace arview::tracker
