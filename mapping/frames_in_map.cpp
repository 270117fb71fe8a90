// Frames an extension was given that the map holds already (mapping/frames_in_map.h): found by
// their image's bytes against the keyframes' images in the map folder, skipped with a note, or
// all of them refused before anything is extracted. Apart from the extension's stages
// (mapping/map_extend.cpp).

#include "mapping/frames_in_map.h"

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <system_error>

#include "base/input_guard.h"
#include "map/map.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// A file's bytes, or nothing when it cannot be read.
std::optional<std::string> BytesOf(const fs::path& file) {
  try {
    return ReadFileUpTo(file, kMaxImageFileBytes);
  } catch (const InputError&) {
    return std::nullopt;
  }
}

// The selected frames whose image is, byte for byte, a keyframe's image kept in the map folder
// (images/, where `arview map` writes a video's frames and each extension copies its own): the same
// frames given to an extension again. Frame name → the keyframe's name. Only the keyframe images of
// a size some selected frame has are read.
std::map<std::string, std::string> FramesAlreadyInMap(const ImageSet& selected, const map::Map& map,
                                                      const fs::path& map_dir) {
  std::map<std::uintmax_t, std::vector<std::string>> by_size;
  std::error_code ec;
  for (const std::string& name : selected.names) {
    const std::uintmax_t size = fs::file_size(selected.root / name, ec);
    if (!ec) by_size[size].push_back(name);
  }
  std::map<std::string, std::string> found;
  for (const map::Keyframe& k : map.keyframes) {
    for (const fs::path& root : {map_dir / "images", map_dir}) {
      const fs::path file = root / k.name;
      const std::uintmax_t size = fs::file_size(file, ec);
      if (ec) continue;
      const auto same_size = by_size.find(size);
      if (same_size == by_size.end()) break;
      const std::optional<std::string> keyframe_bytes = BytesOf(file);
      for (const std::string& name : same_size->second)
        if (keyframe_bytes && !found.count(name) && BytesOf(selected.root / name) == keyframe_bytes) found[name] = k.name;
      break;
    }
  }
  return found;
}

}  // namespace

// `selected` without the frames the map holds already (a note names them; all of them: a MapError,
// before anything is extracted), and `selected_frames` with it.
ImageSet WithoutFramesInMap(const ImageSet& selected, const map::Map& map, const fs::path& map_dir,
                            const recordings::Recording& recording, const MapBuildCallbacks& cb,
                            std::vector<int>* selected_frames) {
  const std::map<std::string, std::string> in_map = FramesAlreadyInMap(selected, map, map_dir);
  if (in_map.empty()) return selected;
  const auto& [first_frame, first_keyframe] = *in_map.begin();
  const std::string example = "'" + first_frame + "' is keyframe '" + first_keyframe + "'";
  if (in_map.size() == selected.names.size()) {
    throw map::MapError("every frame selected from " + recording.root.string() + " is in the map already (" + example +
                        "): nothing to add; the map in " + map_dir.string() + " is as it was");
  }
  if (cb.note) {
    cb.note(std::to_string(in_map.size()) + " of the " + std::to_string(selected.names.size()) + " frames selected from " +
            recording.root.string() + " are in the map already (" + example + "): skipped");
  }
  ImageSet fresh;
  fresh.root = selected.root;
  selected_frames->clear();
  for (const std::string& name : selected.names) {
    if (in_map.count(name)) continue;
    fresh.names.push_back(name);
    fresh.lookup[name] = selected.lookup.at(name);
    selected_frames->push_back(fresh.lookup[name].frame_index);
  }
  return fresh;
}

}  // namespace arview::mapping
