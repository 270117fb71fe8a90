#pragma once
// The room's size, shared by room_scene.cpp (which builds the room) and synth_room.cpp (which
// checks that a board fits on its floor). Private to synth/: nothing outside it includes this.

namespace arview::synth {

// Half the room's length (x) and width (y), and its height, metres: the room is centred on the
// origin, its floor at z = 0 (synth_room.h).
inline constexpr double kHalfX = 3.5, kHalfY = 2.5, kHeight = 2.8;

}  // namespace arview::synth
