#include "tracker/tracker_internal.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "map/map_file.h"
#include "tracker/tracker.h"

namespace arview::tracker {

calib::Pose PredictConstantVelocity(const calib::Pose& last, const calib::Pose& velocity) {
  return velocity * last;
}

calib::Pose RelativeMotion(const calib::Pose& previous, const calib::Pose& last) {
  return last * previous.Inverse();
}

calib::Pose ScaleMotion(const calib::Pose& motion, double ratio) {
  Eigen::AngleAxisd rotation(motion.q_cw);
  rotation.angle() *= ratio;
  return {Eigen::Quaterniond(rotation).normalized(), ratio * motion.t_cw};
}

Track2D3D SpreadTracks(const Track2D3D& tracks, int max_count, int cell, const cv::Size& size) {
  if (static_cast<int>(tracks.pixels.size()) <= max_count) return tracks;
  const int gw = size.width / cell + 1, gh = size.height / cell + 1;
  std::vector<std::vector<int>> cells(static_cast<size_t>(gw) * gh);
  for (size_t i = 0; i < tracks.pixels.size(); ++i) {
    const int gx = std::clamp(static_cast<int>(tracks.pixels[i].x / cell), 0, gw - 1);
    const int gy = std::clamp(static_cast<int>(tracks.pixels[i].y / cell), 0, gh - 1);
    cells[gy * gw + gx].push_back(static_cast<int>(i));
  }
  Track2D3D out;
  for (size_t round = 0; static_cast<int>(out.pixels.size()) < max_count; ++round) {
    bool any = false;
    for (const auto& c : cells) {
      if (round >= c.size()) continue;
      any = true;
      out.pixels.push_back(tracks.pixels[c[round]]);
      out.points.push_back(tracks.points[c[round]]);
      if (static_cast<int>(out.pixels.size()) == max_count) break;
    }
    if (!any) break;
  }
  return out;
}

void CheckTrackable(const map::Map& map, int min_points) {
  if (static_cast<int>(map.points.size()) < min_points) {
    std::ostringstream msg;
    msg << "map has " << map.points.size() << " points, at least " << min_points
        << " are needed to track against it";
    throw TrackerError(msg.str());
  }
  try {
    map::ValidateMap(map, "map");
  } catch (const map::MapError& e) {
    throw TrackerError(e.what());
  }
  if (map.descriptors.rows == 0) throw TrackerError("map has no descriptors to match against");
}

}  // namespace arview::tracker
