#include "mapping/fold_retries.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>

#include "base/cancellation.h"
#include "mapping/map_check.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// The image ids of the initial pair of COLMAP's last mapper run, from its log ("Initializing with
// image pair #3 and #7"); nothing when the log has none.
std::optional<std::pair<std::uint32_t, std::uint32_t>> LastInitialPair(const fs::path& log) {
  std::ifstream in(log);
  std::optional<std::pair<std::uint32_t, std::uint32_t>> pair;
  std::string line;
  unsigned a = 0, b = 0;
  while (std::getline(in, line))
    if (std::sscanf(line.c_str(), "Initializing with image pair #%u and #%u", &a, &b) == 2) pair = {{a, b}};
  return pair;
}

// "frames 2 and 10" for COLMAP image ids, through the map's keyframes (ids it did not register: "#id").
std::string FramesOfImages(const map::Map& map, const std::vector<std::uint32_t>& ids) {
  std::string text;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const auto k = std::find_if(map.keyframes.begin(), map.keyframes.end(),
                                [&](const map::Keyframe& kf) { return kf.colmap_image_id == ids[i]; });
    text += (i == 0 ? "" : i + 1 == ids.size() ? " and " : ", ") +
            (k == map.keyframes.end() ? "#" + std::to_string(ids[i]) : std::to_string(k->frame_index));
  }
  return (ids.size() == 1 ? "frame " : "frames ") + text;
}

// A fold is ranked by its off keyframes, then by the fraction of pairs that disagree: fewer is better.
bool FoldsLess(const MapCheck& a, const MapCheck& b) {
  return std::make_pair(a.disagreeing_frames.size(), a.disagreeing_fraction) <
         std::make_pair(b.disagreeing_frames.size(), b.disagreeing_fraction);
}

}  // namespace

void RetryFoldedMap(int retries, const fs::path& out_dir, const fs::path& log, const MapBuildCallbacks& cb,
                    const FoldRetryStages& stages, MapBuildResult* result) {
  const fs::path sparse = out_dir / "sparse";
  const fs::path tries = out_dir / "fold-tries";
  std::error_code ec;
  fs::remove_all(tries, ec);
  const auto off_frames = [&] {
    return std::to_string(result->check.disagreeing_frames.size()) + " keyframes off, " +
           Percent(result->check.disagreeing_fraction) + " of " + std::to_string(result->check.two_view_pairs) +
           " pairs disagreeing";
  };
  const auto put_back = [&](int k) {  // try k's model in place
    fs::remove_all(sparse, ec);
    fs::rename(tries / std::to_string(k) / "sparse", sparse);
    stages.remember_map();
  };
  std::vector<std::uint32_t> started_from;  // image ids every run began with
  if (const auto pair = LastInitialPair(log)) started_from = {pair->first, pair->second};
  std::string starts = started_from.empty() ? "?" : FramesOfImages(result->map, started_from);
  int best = 0;  // 0: the first model
  MapCheck best_check = result->check;
  int tried = 0;
  while (tried < retries && Folded(result->check)) {
    const std::optional<int> start = KeyframeToStartFrom(result->map, result->check, started_from);
    if (!start) {
      if (cb.note) cb.note("the model looks folded (" + off_frames() + ") and no other keyframe to start from is left");
      break;
    }
    const map::Keyframe& start_frame = result->map.keyframes[*start];
    if (cb.note)
      cb.note("the model looks folded (" + off_frames() + "; COLMAP started from " + starts +
              "): mapping again from frame " + std::to_string(start_frame.frame_index) + ", try " +
              std::to_string(tried + 1) + " of " + std::to_string(retries));
    const fs::path aside = tries / std::to_string(tried);
    fs::create_directories(aside);
    fs::rename(sparse, aside / "sparse");
    stages.forget_map();
    const std::uint32_t start_id = start_frame.colmap_image_id;
    ++tried;
    try {
      stages.map({"--Mapper.init_image_id1", std::to_string(start_id)});
      stages.read_model();
    } catch (const CancelledError&) {
      put_back(best);
      fs::remove_all(tries, ec);
      throw;
    } catch (const Error& e) {
      if (cb.note) cb.note("try " + std::to_string(tried) + " failed: " + e.what());
      break;  // best < tried: put back below
    }
    const auto pair = LastInitialPair(log);
    started_from.push_back(start_id);
    if (pair) started_from.push_back(pair->second);
    starts = pair ? FramesOfImages(result->map, {pair->first, pair->second}) : "?";
    if (FoldsLess(result->check, best_check)) {
      best = tried;
      best_check = result->check;
    }
  }
  result->fold_retries = tried;
  if (best != tried) {
    // An earlier try folded least (every try had the same matches).
    put_back(best);
    stages.read_model();
  } else if (tried > 0) {
    stages.remember_map();
  }
  fs::remove_all(tries, ec);
  if (!cb.note || tried == 0) return;
  if (Folded(result->check))
    cb.note("still folded after mapping again " + std::to_string(tried) + (tried == 1 ? " time" : " times") +
            "; the least folded model is " + (best == 0 ? std::string("the first") : "try " + std::to_string(best)) +
            " (" + off_frames() + ")");
  else
    cb.note("the model of try " + std::to_string(tried) + " is not folded (" + off_frames() + ")");
}


std::string FoldRefusal(const fs::path& out_dir, const MapBuildResult& result) {
  const MapCheck& c = result.check;
  const std::string frames = OffFrameList(c);
  const std::string models = std::to_string(result.fold_retries + 1) + (result.fold_retries == 0 ? " model" : " models");
  const std::string what =
      frames.empty() ? Percent(c.disagreeing_fraction) + " of " + std::to_string(c.two_view_pairs) +
                           " well-matched keyframe pairs disagree with their own matches by over 10 degrees"
                     : "frames " + frames + " are turned from what their own matches say (their pairs disagree by a "
                       "median of over " + Fixed(c.keyframe_off_deg, 1) + " degrees, the map's median pair by " +
                       Fixed(c.median_disagreement_deg, 1) + ")";
  return out_dir.string() + ": the map is folded and was not written: " + what + ", in the least folded of " + models +
         " COLMAP built; map other frames (--frames), film that part again moving the camera sideways, or keep the "
         "map anyway with --keep-folded (figures in " + (out_dir / kMapCheckFileName).string() + ")";
}


}  // namespace arview::mapping
