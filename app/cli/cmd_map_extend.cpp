// arview map extend <map-dir> <recording> [--frames <spec>] [--max-frames N] [--matcher auto|sequential|exhaustive]
//                   [--old-neighbours N] [--max-features N] [--threads N] [--colmap <path>]

#include <iostream>
#include <memory>
#include <string>

#include "app/cli/commands.h"
#include "app/cli/map_console.h"
#include "base/cancellation.h"
#include "base/process.h"
#include "map/map_file.h"
#include "mapping/map_extend.h"

namespace arview::app {

namespace {

struct ExtendArgs {
  std::string map_dir;
  std::string recording;
  std::string frames;
  // The defaults are MapExtendOptions' own.
  int max_frames = mapping::MapExtendOptions().build.max_frames;
  std::string matcher = ToString(mapping::MapExtendOptions().build.matcher);
  int old_neighbours = mapping::MapExtendOptions().old_neighbours;
  int max_features = 0;  // 0: the map's own
  int threads = mapping::MapExtendOptions().build.threads;
  std::string colmap = mapping::MapExtendOptions().build.colmap;
};

using mapping::Fixed;

// "registered 80 of 84 new frames (session-2); points 41,305 -> 52,118 (9,870 seen only by the
// new frames); old keyframes 96 of 96 kept, moved at most 1.2e-15 (path 4.1), turned 0.000 deg"
void PrintExtension(const mapping::MapExtendResult& r, const std::string& map_dir) {
  std::cout << "registered " << r.registered << " of " << r.selected_frames.size() << " new frames (" << r.session
            << "); points " << r.points_before << " -> " << r.points_after << " (" << r.points_new_session_only
            << " seen only by the new frames)\n";
  std::cout << "old keyframes: " << r.old_keyframes_kept << " of " << r.old_keyframes << " kept, poses held: moved at most "
            << r.drift_max << " map units (the old path spans " << Fixed(r.path_extent, 3) << "), turned at most "
            << Fixed(r.drift_rotation_max_deg, 6) << " deg\n";
  int seen = 0;
  for (const auto& s : r.old_support) seen += s.seen_again > 0 ? 1 : 0;
  std::cout << "old keyframes whose points the new frames saw again: " << seen << " of " << r.old_support.size() << "\n";
  if (r.no_longer_match.empty()) {
    std::cout << "old keyframes whose points no longer match: none (none lost a quarter of its observations)\n";
  } else {
    std::cout << "old keyframes whose points no longer match (lost a quarter of their observations or more):";
    for (const auto& s : r.no_longer_match)
      std::cout << " " << s.frame_index << " (" << s.observations_before << " -> " << s.observations_after << ")";
    std::cout << "\n";
  }
  double total = 0;
  std::cout << "stages:";
  for (const auto& t : r.timings) {
    std::cout << " " << t.stage << " " << Fixed(t.seconds, 1) << " s";
    total += t.seconds;
  }
  std::cout << " (total " << Fixed(total, 1) << " s)\n";
  std::cout << "check: " << mapping::DescribeMapCheck(r.check) << "\n";
  std::cout << "wrote " << map_dir << "/{" << map::kMapFileName << ", " << mapping::kMapCheckFileName
            << ", keyframes.txt, map.png, " << mapping::kExtendRecordName << ", database.db, sparse/, images/"
            << r.session << "/}\n";
}

void RunExtend(const ExtendArgs& args) {
  mapping::MapExtendOptions options;
  options.build.frames_spec = args.frames;
  options.build.max_frames = args.max_frames;
  options.build.threads = args.threads;
  options.build.colmap = args.colmap;
  options.old_neighbours = args.old_neighbours;
  if (args.max_features > 0) {
    options.build.max_num_features = args.max_features;
    options.max_features_set = true;
  }
  const ScopedSignalCancellation signals;
  options.build.cancel = signals.token();
  ProgressBar bar;
  const mapping::MapBuildCallbacks callbacks = ConsoleCallbacks(bar, signals.token());
  try {
    options.build.matcher = mapping::ParseMatcherKind(args.matcher);
    const recordings::Recording recording = recordings::LoadRecording(args.recording);
    const mapping::MapExtendResult result = mapping::ExtendMap(args.map_dir, recording, options, callbacks);
    bar.Finish();
    PrintExtension(result, args.map_dir);
  } catch (const CancelledError&) {
    bar.Finish();
    throw;  // its message says which stage stopped, and that the map is as it was
  } catch (const map::MapError& e) {
    bar.Finish();
    if (const auto* stage = dynamic_cast<const mapping::ColmapStageError*>(&e)) {
      std::cerr << "last lines of COLMAP's output (" << stage->log.string() << "):\n";
      for (const auto& line : stage->log_tail) std::cerr << "  | " << line << "\n";
    }
    throw;  // main() says its line
  }
}

}  // namespace

void AddMapExtendCommand(CLI::App& map_command) {
  auto* cmd = map_command.add_subcommand(
      "extend", "Register a new session (other light, moved furniture, a new corner) into a map, keeping its frame");
  auto args = std::make_shared<ExtendArgs>();
  cmd->add_option("map-dir", args->map_dir, "Map directory that 'arview map' wrote")->required();
  cmd->add_option("recording", args->recording, "Recording of the new session, same camera (see 'arview import')")
      ->required();
  cmd->add_option("--frames", args->frames, "Frames of the recording to add, e.g. 670-1339:7 (default: all)");
  cmd->add_option("--max-frames", args->max_frames, "At most this many new frames go to COLMAP (0: no cap)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--matcher", args->matcher,
                  "How the new frames are paired among themselves: auto (exhaustive up to 100 frames, else "
                  "sequential), sequential or exhaustive")
      ->capture_default_str();
  cmd->add_option("--old-neighbours", args->old_neighbours,
                  "Old keyframes each new frame is matched with: those sharing most descriptors with it")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--max-features", args->max_features,
                  "SIFT features per new frame (default: the map's own setting)")
      ->check(CLI::Range(64, 100000));
  cmd->add_option("--threads", args->threads, "Threads COLMAP uses per stage (-1: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(-1, 256));
  cmd->add_option("--colmap", args->colmap, "The COLMAP executable")->capture_default_str();
  cmd->callback([args] { RunExtend(*args); });
}

}  // namespace arview::app
