#include "map/map_rooms.h"

#include <algorithm>
#include <limits>

namespace arview::map {

namespace {

constexpr std::uint32_t kDropped = std::numeric_limits<std::uint32_t>::max();

// Per point, the rooms whose keyframes observe it (a bit per room; venues hold a few rooms, and
// a map of more than 64 treats the rest as one).
std::vector<std::uint64_t> PointRooms(const Map& map) {
  std::vector<std::uint64_t> rooms(map.points.size(), 0);
  for (const Keyframe& k : map.keyframes) {
    if (k.room < 0) continue;
    const std::uint64_t bit = std::uint64_t{1} << std::min(k.room, 63);
    for (const KeyframeObservation& o : k.observations) rooms[o.point] |= bit;
  }
  return rooms;
}

}  // namespace

std::vector<std::vector<int>> RoomNeighbours(const Map& map, const RoomNeighbourOptions& options) {
  const int n = static_cast<int>(map.rooms.size());
  std::vector<std::vector<int>> shared(n, std::vector<int>(n, 0));  // shared[a][a]: a's own points
  for (const std::uint64_t seen_by : PointRooms(map)) {
    for (int a = 0; a < n; ++a) {
      if (!(seen_by >> std::min(a, 63) & 1)) continue;
      for (int b = 0; b < n; ++b)
        if (seen_by >> std::min(b, 63) & 1) ++shared[a][b];
    }
  }
  std::vector<std::vector<int>> neighbours(n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const double smaller = std::min(shared[a][a], shared[b][b]);
      if (b != a && shared[a][b] >= options.min_points && shared[a][b] >= options.min_share * smaller)
        neighbours[a].push_back(b);
    }
  }
  return neighbours;
}

int RoomIndex(const Map& map, const std::string& name) {
  const auto found = std::find(map.rooms.begin(), map.rooms.end(), name);
  if (found != map.rooms.end()) return static_cast<int>(found - map.rooms.begin());
  if (map.rooms.empty()) throw MapError("the map has no rooms (it is one recording's), so no room '" + name + "'");
  std::string names;
  for (const std::string& room : map.rooms) names += (names.empty() ? "" : ", ") + room;
  throw MapError("the map has no room '" + name + "'; its rooms are " + names);
}

std::vector<int> RoomWithNeighbours(const Map& map, int room) {
  std::vector<int> rooms = RoomNeighbours(map)[static_cast<std::size_t>(room)];
  rooms.push_back(room);
  std::sort(rooms.begin(), rooms.end());
  return rooms;
}

Map RoomsPart(const Map& map, const std::vector<int>& rooms) {
  Map part;
  part.camera = map.camera;
  part.frame = map.frame;
  part.rooms = map.rooms;
  std::vector<std::uint32_t> new_keyframe(map.keyframes.size(), kDropped);
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    if (std::find(rooms.begin(), rooms.end(), map.keyframes[k].room) == rooms.end()) continue;
    new_keyframe[k] = static_cast<std::uint32_t>(part.keyframes.size());
    part.keyframes.push_back(map.keyframes[k]);
  }
  // Each kept point's rows of the kept keyframes, packed in the point's order.
  std::vector<std::uint32_t> new_point(map.points.size(), kDropped);
  std::vector<std::uint32_t> new_row(static_cast<std::size_t>(map.descriptors.rows), kDropped);
  std::vector<int> kept_rows;
  for (std::size_t p = 0; p < map.points.size(); ++p) {
    const MapPoint& point = map.points[p];
    const auto first = static_cast<std::uint32_t>(kept_rows.size());
    for (std::uint32_t r = point.first_descriptor; r < point.first_descriptor + point.descriptor_count; ++r) {
      if (new_keyframe[map.descriptor_keyframe[r]] == kDropped) continue;
      new_row[r] = static_cast<std::uint32_t>(kept_rows.size());
      kept_rows.push_back(static_cast<int>(r));
      part.descriptor_point.push_back(static_cast<std::uint32_t>(part.points.size()));
      part.descriptor_keyframe.push_back(new_keyframe[map.descriptor_keyframe[r]]);
    }
    if (kept_rows.size() == first) continue;
    new_point[p] = static_cast<std::uint32_t>(part.points.size());
    MapPoint kept = point;
    kept.first_descriptor = first;
    kept.descriptor_count = static_cast<std::uint32_t>(kept_rows.size()) - first;
    part.points.push_back(kept);
  }
  part.descriptors.create(static_cast<int>(kept_rows.size()), map.descriptors.cols, map.descriptors.type());
  for (std::size_t i = 0; i < kept_rows.size(); ++i) map.descriptors.row(kept_rows[i]).copyTo(part.descriptors.row(static_cast<int>(i)));
  for (Keyframe& k : part.keyframes) {
    for (KeyframeObservation& o : k.observations) {
      o.point = new_point[o.point];
      o.descriptor = new_row[o.descriptor];
    }
  }
  return part;
}

}  // namespace arview::map
