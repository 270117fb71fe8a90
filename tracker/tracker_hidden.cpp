// The hidden points of Tracker (tracker/hidden_points.h), apart from tracker.cpp.

#include <algorithm>

#include "tracker/tracker.h"

namespace arview::tracker {

void Tracker::HideLostTracks(const std::vector<bool>& in_view) {
  const HiddenPointOptions& opt = options_.tracking.hidden;
  if (!opt.enabled) return;
  hidden_.Expire(frames_tracked_, opt.max_age_frames);
  HiddenPoints::Batch lost{frames_tracked_ - 1, last_pyramid_, {}, {}};
  for (std::size_t i = 0; i < last_inliers_.points.size(); ++i) {
    const std::uint32_t id = last_inliers_.points[i];
    if (!in_view[i] || point_stamp_[id] == frame_counter_) continue;  // out of view, or followed
    lost.pixels.push_back(last_inliers_.pixels[i]);
    lost.point_ids.push_back(id);
  }
  hidden_.Add(std::move(lost));
}

int Tracker::RecoverHiddenPoints(const std::vector<cv::Mat>& pyramid, const calib::Pose& projecting,
                                 const std::vector<float>& flow_lk_errors, Correspondences* c) {
  if (hidden_.size() == 0 || flow_lk_errors.empty()) return 0;
  const calib::Camera& camera = resolution_.work();
  const double radius = options_.tracking.hidden.radius_px;
  std::vector<float> errors = flow_lk_errors;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const float patch_bound = static_cast<float>(options_.tracking.moving.patch_error_ratio) * errors[errors.size() / 2];
  // Points the flow follows again (a later track of the same point) are no longer hidden.
  hidden_.Remove([&](std::uint32_t id) { return point_stamp_[id] == frame_counter_; });
  int recovered = 0;
  for (const HiddenPoints::Batch& batch : hidden_.batches()) {
    std::vector<cv::Point2f> from, guesses;
    std::vector<std::uint32_t> ids;
    std::vector<Eigen::Vector2d> expected;
    for (std::size_t i = 0; i < batch.point_ids.size(); ++i) {
      if (point_stamp_[batch.point_ids[i]] == frame_counter_) continue;  // found from an earlier batch
      const Eigen::Vector3d pc = projecting.ToCamera(map_.points[batch.point_ids[i]].xyz);
      if (pc.z() <= 0) continue;
      const Eigen::Vector2d px = camera.Project(pc);
      if (!camera.InImage(px)) continue;
      from.push_back(batch.pixels[i]);
      guesses.emplace_back(px.x(), px.y());
      ids.push_back(batch.point_ids[i]);
      expected.push_back(px);
    }
    if (from.empty()) continue;
    std::vector<float> lk_errors;
    const std::vector<unsigned char> status = FollowByLk(batch.pyramid, pyramid, from, &guesses, &lk_errors);
    for (std::size_t i = 0; i < guesses.size(); ++i) {
      const Eigen::Vector2d px(guesses[i].x, guesses[i].y);
      if (!status[i] || lk_errors[i] > patch_bound || (px - expected[i]).norm() > radius) continue;
      c->pixels.push_back(px);
      c->points.push_back(map_.points[ids[i]].xyz);
      c->point_ids.push_back(ids[i]);
      point_stamp_[ids[i]] = frame_counter_;
      ++recovered;
    }
  }
  hidden_.Remove([&](std::uint32_t id) { return point_stamp_[id] == frame_counter_; });
  return recovered;
}

}  // namespace arview::tracker
