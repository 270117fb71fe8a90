// The tracker's search of the map around a predicted pose: the keyframes that see the followed
// points (covisibility) or, without them, the nearest ones looking the same way, and the map
// points they observe, projected and matched against the frame's SIFT within a radius.

#include "tracker/tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

namespace arview::tracker {
namespace {

int SquaredDistance(const std::uint8_t* a, const std::uint8_t* b) {
  int sum = 0;
  for (int i = 0; i < 128; ++i) {
    const int d = int(a[i]) - int(b[i]);
    sum += d * d;
  }
  return sum;
}

}  // namespace

std::vector<int> Tracker::CovisibleKeyframes(const std::vector<std::uint32_t>& points) const {
  std::vector<int> votes(map_.keyframes.size(), 0);
  for (std::uint32_t p : points)
    for (std::uint32_t k : point_keyframes_[p]) ++votes[k];
  std::vector<std::pair<int, int>> ranked;  // (−votes, keyframe)
  for (size_t k = 0; k < votes.size(); ++k)
    if (votes[k] > 0) ranked.emplace_back(-votes[k], static_cast<int>(k));
  const size_t n = std::min<size_t>(ranked.size(), options_.tracking.guided_keyframes);
  std::partial_sort(ranked.begin(), ranked.begin() + n, ranked.end());
  std::vector<int> best;
  for (size_t i = 0; i < n; ++i) best.push_back(ranked[i].second);
  return best;
}

std::vector<int> Tracker::NearestKeyframes(const calib::Pose& pose) const {
  const Eigen::Vector3d centre = pose.Center();
  const Eigen::Vector3d axis = pose.q_cw.conjugate() * Eigen::Vector3d::UnitZ();
  std::vector<std::pair<double, int>> ranked;
  for (size_t k = 0; k < map_.keyframes.size(); ++k) {
    const calib::Pose& kp = map_.keyframes[k].pose;
    // Keyframes looking more than ~70° away see other surfaces or other sides of them.
    if ((kp.q_cw.conjugate() * Eigen::Vector3d::UnitZ()).dot(axis) < 0.34) continue;
    ranked.emplace_back((kp.Center() - centre).squaredNorm(), static_cast<int>(k));
  }
  const size_t n = std::min<size_t>(ranked.size(), options_.tracking.guided_keyframes);
  std::partial_sort(ranked.begin(), ranked.begin() + n, ranked.end());
  std::vector<int> nearest;
  for (size_t i = 0; i < n; ++i) nearest.push_back(ranked[i].second);
  return nearest;
}

// Guided matching: SIFT keypoints of the frame against map points projected with the predicted
// pose, only within a small radius, with a ratio test between distinct points.
std::vector<MapMatch> Tracker::MatchGuided(const Features& features, const std::vector<GuidedCandidate>& cands,
                                           const map::Map& map, double radius, double ratio,
                                           const cv::Size& size) {
  const int cell = std::max(4, static_cast<int>(std::ceil(radius)));
  const int gw = size.width / cell + 1, gh = size.height / cell + 1;
  std::vector<std::vector<int>> grid(static_cast<size_t>(gw) * gh);
  for (size_t i = 0; i < cands.size(); ++i) {
    const int gx = std::clamp(static_cast<int>(cands[i].pixel.x() / cell), 0, gw - 1);
    const int gy = std::clamp(static_cast<int>(cands[i].pixel.y() / cell), 0, gh - 1);
    grid[gy * gw + gx].push_back(static_cast<int>(i));
  }
  std::vector<MapMatch> matches;
  std::unordered_map<std::uint32_t, size_t> best_for_point;
  const double r2 = radius * radius;
  for (size_t k = 0; k < features.keypoints.size(); ++k) {
    const cv::Point2f& kp = features.keypoints[k].pt;
    const std::uint8_t* desc = features.descriptors.ptr<std::uint8_t>(static_cast<int>(k));
    const int cx = static_cast<int>(kp.x / cell), cy = static_cast<int>(kp.y / cell);
    int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max();
    std::uint32_t best_point = 0;
    for (int gy = std::max(0, cy - 1); gy <= std::min(gh - 1, cy + 1); ++gy) {
      for (int gx = std::max(0, cx - 1); gx <= std::min(gw - 1, cx + 1); ++gx) {
        for (int i : grid[gy * gw + gx]) {
          const GuidedCandidate& c = cands[i];
          if ((c.pixel - Eigen::Vector2d(kp.x, kp.y)).squaredNorm() > r2) continue;
          const map::MapPoint& mp = map.points[c.point];
          int d = std::numeric_limits<int>::max();
          if (c.descriptor != GuidedCandidate::kEveryDescriptor) {
            d = SquaredDistance(desc, map.descriptors.ptr<std::uint8_t>(static_cast<int>(c.descriptor)));
          } else {
            for (std::uint32_t r = 0; r < mp.descriptor_count; ++r)
              d = std::min(d, SquaredDistance(desc, map.descriptors.ptr<std::uint8_t>(
                                                        static_cast<int>(mp.first_descriptor + r))));
          }
          if (d < best) {
            if (c.point != best_point) second = best;
            best = d;
            best_point = c.point;
          } else if (d < second && c.point != best_point) {
            second = d;
          }
        }
      }
    }
    if (best == std::numeric_limits<int>::max()) continue;
    // Distances are squared: compare with the squared ratio.
    if (second != std::numeric_limits<int>::max() &&
        static_cast<double>(best) > ratio * ratio * static_cast<double>(second))
      continue;
    const MapMatch match{static_cast<int>(k), best_point, std::sqrt(static_cast<float>(best))};
    auto [it, inserted] = best_for_point.try_emplace(best_point, matches.size());
    if (inserted) matches.push_back(match);
    else if (match.distance < matches[it->second].distance) matches[it->second] = match;
  }
  return matches;
}


std::vector<Tracker::GuidedCandidate> Tracker::GuidedCandidates(const calib::Pose& pose,
                                                                const std::vector<std::uint32_t>& tracked_points) {
  const calib::Camera& camera = resolution_.work();
  const std::vector<int> keyframes = tracked_points.empty() ? NearestKeyframes(pose) : CovisibleKeyframes(tracked_points);
  std::vector<GuidedCandidate> candidates;
  for (int k : keyframes) {
    for (const auto& obs : map_.keyframes[k].observations) {
      if (point_stamp_[obs.point] == frame_counter_) continue;  // already tracked or queued
      point_stamp_[obs.point] = frame_counter_;
      const Eigen::Vector3d pc = pose.ToCamera(map_.points[obs.point].xyz);
      if (pc.z() <= 0) continue;
      const Eigen::Vector2d px = camera.Project(pc);
      if (camera.InImage(px)) candidates.push_back({px, obs.point});
    }
  }
  return candidates;
}

}  // namespace arview::tracker
