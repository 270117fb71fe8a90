#pragma once
// A venue's map in parts (issue 55): a device in one room loads that room and the rooms next to it
// only (`--room` of `arview track`, `replay` and `run`), not every room of the venue. Rooms are
// next to each other when their keyframes see the same map points (a door both see through, the
// frames of a walk from one into the other); `arview map info` lists each room's neighbours.

#include <string>
#include <vector>

#include "map/map.h"

namespace arview::map {

// Two rooms are next to each other when their keyframes observe at least `min_points` common
// points and at least `min_share` of the points of the smaller room: a door both see through is a
// real part of a room's points, where a few dozen matched across the venue (a glimpse through two
// doors, a texture repeated) are not. The rendered venue's rooms in a row share 800-1,600 points
// with the next room (of ~10,000 each) and 50-100 with the room after it.
struct RoomNeighbourOptions {
  int min_points = 20;
  double min_share = 0.02;
};

// Per room (Map::rooms order), the rooms next to it, in room order. Empty for a map without rooms.
std::vector<std::vector<int>> RoomNeighbours(const Map& map, const RoomNeighbourOptions& options = {});

// The index of the room named `name`; MapError naming the rooms there are when there is none
// (or the map has no rooms: it is one recording's).
int RoomIndex(const Map& map, const std::string& name);

// `map` cut down to the keyframes of `rooms` (indices into Map::rooms) and the points they
// observe, each point's descriptors those of the kept keyframes' observations; the camera, the
// frame and the room names as they are. A consistent map (map/map_file.h ValidateMap) when
// `map` is one.
Map RoomsPart(const Map& map, const std::vector<int>& rooms);

// `room` and its neighbours (RoomNeighbours), in room order.
std::vector<int> RoomWithNeighbours(const Map& map, int room);

}  // namespace arview::map
