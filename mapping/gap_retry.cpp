#include "mapping/gap_retry.h"

#include <optional>
#include <unordered_set>

#include "base/cancellation.h"
#include "mapping/map_check.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// "frames 180-296 (30)" for the message.
std::string StretchText(const LeftOutStretch& s) {
  return s.count == 1 ? "frame " + std::to_string(s.first)
                      : "frames " + std::to_string(s.first) + "-" + std::to_string(s.last) + " (" +
                            std::to_string(s.count) + ")";
}

std::string StretchList(const std::vector<LeftOutStretch>& stretches) {
  std::string text;
  for (std::size_t i = 0; i < stretches.size(); ++i) text += (i ? ", " : "") + StretchText(stretches[i]);
  return text;
}

std::string RegisteredText(const MapBuildResult& result) {
  return std::to_string(result.map.keyframes.size()) + " of " + std::to_string(result.selected_frames.size());
}

}  // namespace

std::vector<LeftOutStretch> LeftOutStretches(const std::vector<int>& selected, const map::Map& map, int min_count) {
  std::unordered_set<int> registered;
  for (const map::Keyframe& k : map.keyframes) registered.insert(k.frame_index);
  std::vector<LeftOutStretch> stretches;
  std::optional<LeftOutStretch> open;
  const auto close = [&] {
    if (open && open->count >= min_count) stretches.push_back(*open);
    open.reset();
  };
  for (int frame : selected) {
    if (registered.count(frame)) {
      close();
    } else if (open) {
      open->last = frame;
      ++open->count;
    } else {
      open = LeftOutStretch{frame, frame, 1};
    }
  }
  close();
  return stretches;
}

std::vector<std::string> LowAngleMapperArgs(double angle_deg) {
  const std::string angle = Fixed(angle_deg, 2);
  return {"--Mapper.tri_min_angle", angle, "--Mapper.filter_min_tri_angle", angle};
}

std::vector<std::string> RetryLeftOutFrames(const MapBuildOptions& options, const fs::path& out_dir,
                                            const MapBuildCallbacks& cb, const FoldRetryStages& stages,
                                            MapBuildResult* result) {
  if (options.gap_retry_angle_deg <= 0) return {};
  const std::vector<LeftOutStretch> stretches =
      LeftOutStretches(result->selected_frames, result->map, options.gap_retry_min_frames);
  if (stretches.empty()) return {};
  const std::vector<std::string> low_angle = LowAngleMapperArgs(options.gap_retry_angle_deg);
  if (cb.note)
    cb.note("COLMAP registered " + RegisteredText(*result) + " frames and left out " + StretchList(stretches) +
            ": mapping again with triangulation angles down to " + Fixed(options.gap_retry_angle_deg, 1) +
            " degrees from 1.5, which lets COLMAP register frames that see only a part of the scene filmed from "
            "close together (the walk after a fast turn)");
  const fs::path sparse = out_dir / "sparse";
  const fs::path aside = out_dir / "gap-try";
  std::error_code ec;
  fs::remove_all(aside, ec);
  fs::create_directories(aside);
  fs::rename(sparse, aside / "sparse");
  stages.forget_map();
  const std::size_t first_registered = result->map.keyframes.size();
  const bool first_folded = Folded(result->check);
  const auto put_back_first = [&] {
    fs::remove_all(sparse, ec);
    fs::rename(aside / "sparse", sparse);
    fs::remove_all(aside, ec);
    stages.remember_map();
  };
  try {
    stages.map(low_angle);
    stages.read_model();
  } catch (const CancelledError&) {
    put_back_first();
    throw;
  } catch (const Error& e) {
    if (cb.note) cb.note("mapping again failed (" + std::string(e.what()) + "); the first model is kept");
    put_back_first();
    stages.read_model();
    return {};
  }
  const bool better = result->map.keyframes.size() > first_registered && (first_folded || !Folded(result->check));
  if (!better) {
    if (cb.note)
      cb.note("mapping again registered " + RegisteredText(*result) + " frames" +
              (Folded(result->check) ? " but folded" : "") + "; the first model (" + std::to_string(first_registered) +
              ") is kept");
    put_back_first();
    stages.read_model();
    return {};
  }
  fs::remove_all(aside, ec);
  stages.remember_map();
  const std::vector<LeftOutStretch> still =
      LeftOutStretches(result->selected_frames, result->map, options.gap_retry_min_frames);
  if (cb.note)
    cb.note("mapping again registered " + RegisteredText(*result) + " frames" +
            (still.empty() ? std::string() : "; still left out: " + StretchList(still)));
  return low_angle;
}

}  // namespace arview::mapping
