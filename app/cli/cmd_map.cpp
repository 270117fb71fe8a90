// arview map <recording> --out <map-dir> [--frames <spec>] [--matcher auto|sequential|exhaustive] [--match-engine auto|arview|colmap]
//            [--max-frames N] [--refine-intrinsics] [--threads N] [--colmap <path>] [--max-features N] [--preset quality|fast]
//            [--fold-retries N] [--keep-folded]
// arview map info <map-dir>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "app/cli/commands.h"
#include "app/cli/map_console.h"
#include "base/cancellation.h"
#include "base/process.h"
#include "map/map_file.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/map_check.h"

namespace arview::app {

namespace {

namespace fs = std::filesystem;

struct MapArgs {
  std::string recording;
  std::string out;
  std::string frames;
  std::string matcher = "auto";
  std::string match_engine = "auto";
  int max_frames = 300;
  bool refine_intrinsics = false;
  int threads = 2;
  std::string colmap = "colmap";
  std::string preset = "quality";
  int max_features = 0;  // 0: the preset's
  int fold_retries = mapping::MapBuildOptions().fold_retries;
  bool keep_folded = false;
  std::string info_dir;
  bool info_recheck = false;
};

using mapping::Fixed;

void RunMap(const MapArgs& args) {
  if (args.recording.empty()) throw CommandError("map: the recording folder is required (arview map <recording> --out <map-dir>)", 2);
  if (args.out.empty()) throw CommandError("map: --out <map-dir> is required", 2);
  mapping::MapBuildOptions options;
  options.frames_spec = args.frames;
  options.max_frames = args.max_frames;
  options.refine_intrinsics = args.refine_intrinsics;
  options.threads = args.threads;
  options.colmap = args.colmap;
  if (args.preset == "fast") options.UseFastPreset();
  if (args.max_features > 0) options.max_num_features = args.max_features;
  options.fold_retries = args.fold_retries;
  options.keep_folded = args.keep_folded;
  const ScopedSignalCancellation signals;
  options.cancel = signals.token();
  ProgressBar bar;
  const mapping::MapBuildCallbacks callbacks = ConsoleCallbacks(bar, signals.token());
  try {
    options.matcher = mapping::ParseMatcherKind(args.matcher);
    options.match_engine = mapping::ParseMatchEngine(args.match_engine);
    const recordings::Recording recording = recordings::LoadRecording(args.recording);
    const auto result = mapping::BuildMap(recording, args.out, options, callbacks);
    bar.Finish();
    const auto stats = map::ComputeStats(result.map);
    std::cout << "registered " << result.map.keyframes.size() << " of " << result.selected_frames.size()
              << " frames; " << stats.points << " points, mean track length " << Fixed(stats.mean_track_length, 2)
              << ", mean reprojection error " << Fixed(stats.mean_reprojection_error, 3) << " px\n";
    double total = 0;
    std::cout << "stages:";
    for (const auto& t : result.timings) {
      std::cout << " " << t.stage << " " << (t.skipped ? "skipped" : Fixed(t.seconds, 1) + " s");
      total += t.seconds;
    }
    std::cout << " (total " << Fixed(total, 1) << " s)\n";
    std::cout << "check: " << mapping::DescribeMapCheck(result.check) << "\n";
    std::cout << "wrote " << args.out << "/{" << map::kMapFileName << ", " << mapping::kMapCheckFileName
              << ", keyframes.txt, map.png, database.db}, COLMAP model " << result.model_dir.string() << "\n";
  } catch (const mapping::ColmapStageError& e) {
    bar.Finish();
    std::cerr << "last lines of COLMAP's output (" << e.log.string() << "):\n";
    for (const auto& line : e.log_tail) std::cerr << "  | " << line << "\n";
    throw CommandError(e.what());
  } catch (const CancelledError&) {
    bar.Finish();
    throw;  // its message says which stage stopped and what was kept
  } catch (const ProcessError& e) {
    throw CommandError(e.what());
  } catch (const map::MapError& e) {
    throw CommandError(e.what());
  } catch (const recordings::RecordingError& e) {
    throw CommandError(e.what());
  }
}

// A folder where `arview map` refused a folded map holds its check.json but no map file: say
// why, rather than "map file missing".
void RequireMapNotRefused(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec) || fs::exists(fs::path(dir) / map::kMapFileName, ec)) return;
  const auto check = mapping::ReadMapCheck(fs::path(dir) / mapping::kMapCheckFileName);
  if (!check || !mapping::Folded(*check)) return;
  throw CommandError((fs::path(dir) / map::kMapFileName).string() +
                     ": no map file: arview map refused the map it built here, which " + check->warnings.back());
}

void RunInfo(const std::string& dir, bool recheck) {
  try {
    RequireMapNotRefused(dir);
    // Before anything is printed, so that a folder without COLMAP's model fails with one line.
    std::error_code ec;  // a name too long or a folder that cannot be searched: LoadMap says so, naming it
    if (recheck) mapping::RecheckMap(fs::is_regular_file(dir, ec) ? fs::path(dir).parent_path() : fs::path(dir));
    const auto start = std::chrono::steady_clock::now();
    const map::Map map = map::LoadMap(dir);
    const double load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const auto s = map::ComputeStats(map);
    int first = -1, last = -1;
    for (const auto& k : map.keyframes) {
      if (first < 0 || k.frame_index < first) first = k.frame_index;
      last = std::max(last, k.frame_index);
    }
    const auto& c = map.camera;
    std::cout << "map:                 " << dir << "\n"
              << "camera:              " << c.width << "x" << c.height << ", fx " << c.fx << ", fy " << c.fy << ", cx "
              << c.cx << ", cy " << c.cy << "\n"
              << "keyframes:           " << s.keyframes << " (frames " << first << " to " << last << ")\n"
              << "points:              " << s.points << "\n"
              << "mean track length:   " << Fixed(s.mean_track_length, 2) << "\n"
              << "observations:        " << s.observations << "\n"
              << "reprojection error:  mean " << Fixed(s.mean_reprojection_error, 3) << " px, median "
              << Fixed(s.median_reprojection_error, 3) << " px (COLMAP's mean point error "
              << Fixed(s.mean_colmap_point_error, 3) << " px)\n"
              << "descriptors:         " << s.descriptors << " (128 x uint8, "
              << Fixed(static_cast<double>(s.descriptors) * 128 / (1 << 20), 1) << " MiB)\n"
              << "load time:           " << Fixed(load_ms, 1) << " ms\n";
    const fs::path folder = fs::is_directory(dir, ec) ? fs::path(dir) : fs::path(dir).parent_path();
    if (const auto check = mapping::ReadMapCheck(folder / mapping::kMapCheckFileName)) {
      std::cout << "check:               " << mapping::DescribeMapCheck(*check) << "\n";
      for (const auto& warning : check->warnings) std::cout << "warning:             the map " << warning << "\n";
      if (!check->flagged()) std::cout << "                     (nothing flagged)\n";
    } else {
      std::cout << "check:               not recorded (" << mapping::kMapCheckFileName
                << " is written by arview map since issue 17)\n";
    }
    if (const auto why = map::DegeneratePoints(map)) {
      std::cout << "warning:             the map's points cannot hold a floor ('arview place' refuses the map): " << *why
                << "\n";
    }
  } catch (const map::MapError& e) {
    throw CommandError(e.what());
  }
}

}  // namespace

void AddMapCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("map", "Build the map of a scene from a recording with COLMAP ('map info' describes one)");
  auto args = std::make_shared<MapArgs>();
  cmd->add_option("recording", args->recording, "Recording folder (see 'arview import')");
  cmd->add_option("--out", args->out, "Map directory to write (created; a re-run skips unchanged stages)");
  cmd->add_option("--frames", args->frames, "Frames to use, e.g. 0-46:2 or 1,5,9-12 (default: all)");
  cmd->add_option("--matcher", args->matcher, "auto (exhaustive up to 100 frames, else sequential), sequential or exhaustive")
      ->capture_default_str();
  cmd->add_option("--match-engine", args->match_engine,
                  "auto (arview for frames 1600 px or longer, else colmap), arview (a kd-tree per frame, COLMAP verifies: "
                  "3.3x faster on phone video) or colmap (COLMAP's own matcher)")
      ->capture_default_str();
  cmd->add_option("--max-frames", args->max_frames, "At most this many frames go to COLMAP (0: no cap)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--refine-intrinsics", args->refine_intrinsics, "Let COLMAP refine the recording's camera");
  cmd->add_option("--threads", args->threads, "Threads COLMAP uses per stage (-1: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(-1, 256));
  cmd->add_option("--colmap", args->colmap, "The COLMAP executable")->capture_default_str();
  cmd->add_option("--max-features", args->max_features,
                  "SIFT features per image (COLMAP's SiftExtraction.max_num_features; default: the preset's, "
                  "quality 8192, fast 850): fewer map faster")
      ->check(CLI::Range(64, 100000));
  cmd->add_option("--preset", args->preset,
                  "quality: COLMAP's own feature and bundle-adjustment settings; fast: 850 features, one "
                  "orientation, fewer bundle adjustments (about a third less time, about twice the error)")
      ->capture_default_str()
      ->check(CLI::IsMember({"quality", "fast"}));
  cmd->add_option("--fold-retries", args->fold_retries,
                  "When the self-check finds part of the path registered at wrong rotations (a fold), run COLMAP's "
                  "mapper again on the same matches up to this many times, each time starting from a keyframe the "
                  "check found right; a map still folded after them is refused (see --keep-folded)")
      ->capture_default_str()
      ->check(CLI::Range(0, 10));
  cmd->add_flag("--keep-folded", args->keep_folded,
                "Write the map even when it is still folded after --fold-retries (the least folded model, with "
                "the warning); by default such a map is refused");

  auto* info = cmd->add_subcommand("info", "Describe a map: frames, points, track length, reprojection error, load time");
  info->add_option("map-dir", args->info_dir, "Map directory (or its map.arvmap)")->required();
  info->add_flag("--recheck", args->info_recheck,
                 "Run the map's self-check again from the COLMAP model and database in its folder and rewrite "
                 "check.json (maps built before a check existed)");
  info->callback([args] { RunInfo(args->info_dir, args->info_recheck); });
  AddMapExtendCommand(*cmd);
  cmd->callback([args, cmd] {
    if (!cmd->get_subcommands().empty()) return;  // `map info`, `map extend`: their own callbacks ran
    RunMap(*args);
  });
}

}  // namespace arview::app
