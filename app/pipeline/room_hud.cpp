#include "app/pipeline/room_hud.h"

namespace arview::app {

std::vector<std::string> RoomHud::Update(const std::string& room, double timestamp) {
  if (room.empty()) {
    // Lost (or no rooms at all): where the camera was last is what the user can act on.
    if (room_.empty()) return {};
    return {"room: none while lost (last in " + room_ + ")"};
  }
  if (room != room_) {
    // The first room found is where the session starts, not a change.
    previous_room_ = room_;
    room_ = room;
    changed_at_ = timestamp;
  }
  std::vector<std::string> lines = {"room: " + room_};
  if (!previous_room_.empty() && timestamp - changed_at_ < kChangeNoteSeconds) {
    lines.push_back("room changed: " + previous_room_ + " -> " + room_);
  }
  return lines;
}

}  // namespace arview::app
