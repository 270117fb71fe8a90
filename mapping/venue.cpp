#include "mapping/venue.h"

#include "map/map_rooms.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>

#include "base/atomic_file.h"
#include "base/input_guard.h"
#include "base/library_errors.h"

namespace arview::mapping {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// The camera every room must share: one camera in COLMAP's database, one in the map.
bool SameCamera(const calib::Camera& a, const calib::Camera& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.dist == b.dist && a.calibrated == b.calibrated;
}

// A room's name: its folder's, with "-2", "-3" ... after a name taken.
std::string UniqueName(const fs::path& folder, const std::vector<VenueRoom>& rooms) {
  std::string base = folder.filename().string();
  if (base.empty() || base == "." || base == "..") base = "room";
  std::string name = base;
  for (int k = 2; std::any_of(rooms.begin(), rooms.end(), [&](const VenueRoom& r) { return r.name == name; }); ++k)
    name = base + "-" + std::to_string(k);
  return name;
}

// <rooms_dir>/<name> a link to `target` (an older link of that name replaced).
void LinkRoom(const fs::path& rooms_dir, const std::string& name, const fs::path& target) {
  const fs::path link = rooms_dir / name;
  std::error_code ec;
  if (fs::is_symlink(link, ec) && fs::read_symlink(link, ec) == target) return;
  fs::remove(link, ec);
  fs::create_directory_symlink(target, link, ec);
  if (ec) throw map::MapError(link.string() + ": cannot link it to the recording " + target.string() + " (" + ec.message() + ")");
}

}  // namespace

recordings::Recording VenueRecording(const std::vector<fs::path>& folders, const fs::path& out_dir,
                                     std::vector<VenueRoom>* rooms) {
  if (folders.size() < 2) throw map::MapError("a venue needs two recordings or more (got " + std::to_string(folders.size()) + ")");
  std::vector<recordings::Recording> loaded;
  rooms->clear();
  std::set<fs::path> seen;
  int next_frame = 0;
  for (const fs::path& folder : folders) {
    const fs::path absolute = fs::weakly_canonical(fs::absolute(folder));
    if (!seen.insert(absolute).second) throw map::MapError(folder.string() + ": the same recording given twice");
    recordings::Recording recording = recordings::LoadRecording(folder);
    if (recording.IsVideo())
      throw map::MapError(folder.string() + ": a video recording; a venue takes still-image recordings (frames/*.png)");
    if (!loaded.empty() && !SameCamera(recording.camera, loaded.front().camera))
      throw map::MapError(folder.string() + ": its camera is not the camera of " + folders.front().string() +
                          " (a venue's recordings share one camera: COLMAP's database and the map hold one)");
    VenueRoom room;
    room.name = UniqueName(absolute, *rooms);
    room.recording = absolute;
    room.first_frame = next_frame;
    room.frames = static_cast<int>(recording.frames.size());
    next_frame += room.frames;
    rooms->push_back(room);
    loaded.push_back(std::move(recording));
  }
  recordings::Recording venue;
  venue.root = fs::absolute(out_dir).lexically_normal() / "rooms";
  venue.camera = loaded.front().camera;
  std::error_code ec;
  fs::create_directories(venue.root, ec);
  if (ec) throw map::MapError(venue.root.string() + ": cannot create it (" + ec.message() + ")");
  for (std::size_t r = 0; r < loaded.size(); ++r) {
    LinkRoom(venue.root, (*rooms)[r].name, (*rooms)[r].recording);
    for (const recordings::FrameEntry& frame : loaded[r].frames) {
      recordings::FrameEntry entry = frame;
      entry.path = (fs::path((*rooms)[r].name) / frame.path).lexically_normal().generic_string();
      venue.frames.push_back(entry);
    }
  }
  return venue;
}

void NameRooms(const std::vector<VenueRoom>& rooms, map::Map* map) {
  map->rooms.clear();
  for (const VenueRoom& room : rooms) map->rooms.push_back(room.name);
  for (map::Keyframe& k : map->keyframes) {
    const auto in = std::find_if(rooms.begin(), rooms.end(), [&](const VenueRoom& r) { return r.Holds(k.frame_index); });
    k.room = in == rooms.end() ? -1 : static_cast<int>(in - rooms.begin());
  }
}

void WriteVenueFile(std::vector<VenueRoom> rooms, const map::Map& map, const fs::path& out_dir) {
  json list = json::array();
  for (VenueRoom& room : rooms) {
    room.keyframes = static_cast<int>(std::count_if(map.keyframes.begin(), map.keyframes.end(),
                                                    [&](const map::Keyframe& k) { return room.Holds(k.frame_index); }));
    list.push_back({{"name", room.name},
                    {"recording", room.recording.string()},
                    {"first_frame", room.first_frame},
                    {"frames", room.frames},
                    {"keyframes", room.keyframes}});
  }
  WriteFileAtomically(out_dir / kVenueFileName, json{{"venue", 1}, {"rooms", list}}.dump(2) + "\n");
}

std::optional<std::vector<VenueRoom>> ReadVenueFile(const fs::path& map_dir) {
  const fs::path file = map_dir / kVenueFileName;
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  return NamingInput<map::MapError>(file.string(), [&] {
    try {
      const json j = json::parse(ReadFileUpTo(file, 1 << 20));
      if (j.at("venue").get<int>() != 1) throw map::MapError(file.string() + ": a venue file of another version");
      std::vector<VenueRoom> rooms;
      for (const json& r : j.at("rooms")) {
        VenueRoom room;
        room.name = r.at("name").get<std::string>();
        room.recording = r.at("recording").get<std::string>();
        room.first_frame = r.at("first_frame").get<int>();
        room.frames = r.at("frames").get<int>();
        room.keyframes = r.at("keyframes").get<int>();
        rooms.push_back(room);
      }
      return rooms;
    } catch (const json::exception& e) {
      throw map::MapError(file.string() + ": not a venue file (" + e.what() + ")");
    } catch (const InputError& e) {
      throw map::MapError(e.what());
    }
  });
}

std::string DescribeRoom(const VenueRoom& room) {
  return room.name + ": " + std::to_string(room.frames) + " frames (" + std::to_string(room.first_frame) + "-" +
         std::to_string(room.first_frame + room.frames - 1) + "), " + std::to_string(room.keyframes) + " registered";
}

std::vector<std::string> DescribeMapRooms(const map::Map& map, const std::vector<VenueRoom>& venue) {
  std::vector<std::string> lines;
  const std::vector<std::vector<int>> neighbours = map::RoomNeighbours(map);
  for (std::size_t r = 0; r < map.rooms.size(); ++r) {
    const auto keyframes = std::count_if(map.keyframes.begin(), map.keyframes.end(),
                                         [&](const map::Keyframe& k) { return k.room == static_cast<int>(r); });
    std::string line = map.rooms[r] + ": " + std::to_string(keyframes) + " keyframes";
    const auto named = std::find_if(venue.begin(), venue.end(), [&](const VenueRoom& v) { return v.name == map.rooms[r]; });
    if (named != venue.end())
      line += " of " + std::to_string(named->frames) + " frames (" + std::to_string(named->first_frame) + "-" +
              std::to_string(named->first_frame + named->frames - 1) + ")";
    std::string next;
    for (const int n : neighbours[r]) next += (next.empty() ? "" : ", ") + map.rooms[static_cast<std::size_t>(n)];
    line += next.empty() ? "; next to no other room" : "; next to " + next;
    lines.push_back(line);
  }
  return lines;
}

}  // namespace arview::mapping
