#pragma once
// A venue of rooms joined by doors (`arview synth venue`): `rooms` rooms in a row along x, each
// 5 x 4 x 2.6 m, every two neighbours joined by a doorway in the wall they share. Walls, floors and
// ceilings carry textures drawn from a seed, different in every room: a photo hung in two rooms
// would be matched across them, and COLMAP would join the rooms on it. The camera's walk: a turn
// round each room looking at its walls, then straight through the door into the next.
//
// World frame: metres, z up, floor at z = 0; room k spans x in [x0 + k L, x0 + (k + 1) L] with
// x0 = -rooms L / 2, and y in [-W / 2, W / 2]; the doors are centred on y = 0.

#include <Eigen/Core>

#include <cstdint>
#include <string>

#include "calib/pose.h"
#include "synth/synth_room.h"

namespace arview::synth {

struct VenueLayout {
  int rooms = 3;
  double room_length = 5.0;  // along x, the way the walk goes
  double room_width = 4.0;   // along y
  double height = 2.6;
  double door_width = 1.0, door_height = 2.1;

  double RoomCentreX(int room) const { return (room + 0.5 - rooms / 2.0) * room_length; }
  // The room whose floor holds the point (x and y); -1 outside every room.
  int RoomAt(const Eigen::Vector3d& point) const;
  // "room-1", "room-2", ...: the names the recordings and the map's rooms take.
  static std::string RoomName(int room);
};

// Most rooms the renderer's far plane (20 m) sees through, end to end.
inline constexpr int kMaxVenueRooms = 4;

// The venue's geometry and textures (RoomScene: its panels are the textured rectangles); the same
// for a seed.
RoomScene MakeVenueScene(const VenueLayout& layout, uint64_t seed);

// The camera's walk through the venue over `duration` seconds: in each room a full turn on a
// circle of 1 m round its centre, looking out at the walls (the turn starts and ends on the side
// of the next door, looking through it), then a walk along y = 0 through the door to the same
// point of the next room. Each stretch starts and ends at rest (smootherstep), so the path is
// smooth; a turn takes 3 shares of the time, a walk from one room to the next 2 (720 frames
// through 3 rooms: a turn in 5.5 s, 5 m in 3.7 s). Camera at 1.5 m, looking 6 degrees down.
class VenueWalk {
 public:
  VenueWalk(const VenueLayout& layout, double duration);
  calib::Pose At(double t) const;
  // When the walk crosses from room k into room k + 1 (the door's plane).
  double DoorTime(int room) const;

  static constexpr double kTurnRadius = 1.0, kCameraHeight = 1.5, kPitch = -0.105;
  static constexpr double kTurnShare = 3, kWalkShare = 2;

 private:
  VenueLayout layout_;
  double unit_;  // seconds per share
};

}  // namespace arview::synth
