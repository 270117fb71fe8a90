#pragma once
// `arview map <rec> <rec> ... --out <venue>`: several recordings (rooms, corridors, sessions) of
// one place mapped as one map (docs/mapping.md, "A venue of several recordings"). The recordings
// become one still-image recording whose folder is <venue>/rooms: each room a link to its
// recording's folder, its frames named <room>/<frame path> and numbered after the rooms before
// it; BuildMap then maps them as one (every image in one database, matched across rooms as
// within them; with --leaf-size, leaves cut where the match graph is weakest, whatever the
// rooms). <venue>/venue.json names the rooms, their frames in the venue's numbering and how
// many of them the map registered; `arview map info` lists them.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "map/map.h"
#include "recordings/recording.h"

namespace arview::mapping {

struct VenueRoom {
  std::string name;                   // the recording folder's name (made unique: "hall", "hall-2")
  std::filesystem::path recording;    // the recording folder, absolute
  int first_frame = 0;                // the venue's index of the room's first frame
  int frames = 0;
  int keyframes = 0;                  // frames of the room the map registered

  bool Holds(int venue_frame) const { return venue_frame >= first_frame && venue_frame < first_frame + frames; }
};

constexpr const char* kVenueFileName = "venue.json";

// The recordings (folders) as one recording under <out_dir>/rooms (the links made or renewed
// there) and the rooms it holds. Throws MapError, before anything is written, for fewer than two
// recordings, a video recording (frames.txt naming one video file), a camera other than the
// first recording's, or the same folder twice; recordings::RecordingError for a folder that is
// not a recording.
recordings::Recording VenueRecording(const std::vector<std::filesystem::path>& recordings,
                                     const std::filesystem::path& out_dir, std::vector<VenueRoom>* rooms);

// The rooms' names in `map` and each keyframe's room (the room holding its frame; -1: none).
void NameRooms(const std::vector<VenueRoom>& rooms, map::Map* map);

// Each room's keyframes counted from the map, then <out_dir>/venue.json written (atomically).
void WriteVenueFile(std::vector<VenueRoom> rooms, const map::Map& map, const std::filesystem::path& out_dir);

// The rooms of <map_dir>/venue.json; nothing when the map is not a venue's. Throws MapError for a
// file that is not a venue file.
std::optional<std::vector<VenueRoom>> ReadVenueFile(const std::filesystem::path& map_dir);

// "hall: 24 frames (0-23), 24 registered"
std::string DescribeRoom(const VenueRoom& room);

// One line per room of the map file (map::Map::rooms): "hall: 24 keyframes", and with the room of
// that name in `venue` (venue.json) its frames: "hall: 24 keyframes of 24 frames (0-23)"; then
// the rooms next to it (map/map_rooms.h, what `--room` loads with it): "; next to office".
std::vector<std::string> DescribeMapRooms(const map::Map& map, const std::vector<VenueRoom>& venue);

}  // namespace arview::mapping
