#pragma once
// The HUD's lines for the room of a venue's map (tracker::FrameResult::room): the room the frame
// is in and, for a few seconds after it changed, which room the camera came from. A map without
// rooms gives no lines. Not thread-safe: the render thread updates it once per frame, in order.

#include <string>
#include <vector>

namespace arview::app {

class RoomHud {
 public:
  // How long the note of a change stays (seconds of the frames' own timestamps, so that a replay
  // shows it on the same frames however fast it runs): long enough to read two words.
  static constexpr double kChangeNoteSeconds = 3.0;

  // The lines for a frame at `timestamp` whose room is `room` (empty: lost, or a map without
  // rooms). Frames come in order.
  std::vector<std::string> Update(const std::string& room, double timestamp);

 private:
  std::string room_;           // the last room a frame was localized in; empty: none yet
  std::string previous_room_;  // the room before room_, while the change is noted
  double changed_at_ = 0;      // timestamp of the first frame in room_ after previous_room_
};

}  // namespace arview::app
