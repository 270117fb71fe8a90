// arview map <recording> [<recording> ...] --out <map-dir> [--frames <spec>] [--matcher auto|sequential|exhaustive] [--match-engine auto|arview|colmap]
//            [--max-frames N] [--refine-intrinsics] [--threads N] [--colmap <path>] [--max-features N] [--preset quality|fast]
//            [--fold-retries N] [--keep-folded] [--gap-retry-angle DEG] [--board CxR --square M [--board-off-floor] | --no-metric]
//            [--leaf-size N [--leaf-overlap N]] [--engine local|slurm [--slurm-chunk N] [--slurm-partition P] [--slurm-cpus N] [--slurm-time-limit MIN]]
// arview map info <map-dir>
// arview map scale <map-dir> [<recording>] (--board CxR --square M [--board-off-floor] | --distance M --from .. --to ..)

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
#include "app/cli/numeric_flags.h"
#include "base/cancellation.h"
#include "base/process.h"
#include "map/map_file.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/map_check.h"
#include "mapping/venue.h"

namespace arview::app {

namespace {

namespace fs = std::filesystem;

using mapping::Fixed;

struct MapArgs {
  std::vector<std::string> recordings;  // two or more: a venue (mapping/venue.h)
  std::string out;
  std::string frames;
  // The defaults are MapBuildOptions' own.
  std::string matcher = ToString(mapping::MapBuildOptions().matcher);
  std::string match_engine = ToString(mapping::MapBuildOptions().match_engine);
  int max_frames = mapping::MapBuildOptions().max_frames;
  bool refine_intrinsics = mapping::MapBuildOptions().refine_intrinsics;
  int threads = mapping::MapBuildOptions().threads;
  std::string colmap = mapping::MapBuildOptions().colmap;
  std::string preset = "quality";
  int max_features = 0;  // 0: the preset's
  int fold_retries = mapping::MapBuildOptions().fold_retries;
  bool keep_folded = mapping::MapBuildOptions().keep_folded;
  double gap_retry_angle = mapping::MapBuildOptions().gap_retry_angle_deg;
  // A venue in leaves (mapping/leaf_mapping.h).
  int leaf_size = 0;
  int leaf_overlap = mapping::MapBuildOptions().leaf_overlap;
  int cross_room_neighbours = mapping::MapBuildOptions().cross_rooms.neighbours;
  bool leaves_within_rooms = false;
  std::string engine = "local";
  std::string slurm_partition;
  int slurm_cpus = 0;
  int slurm_time_limit = 0;
  int slurm_chunk = 0;
  std::string info_dir;
  bool info_recheck = false;
  // Metres and up (mapping/metric_frame.h).
  std::string board;                 // inner corners, e.g. 9x6
  double square = 0;                 // metres
  bool board_off_floor = false;
  bool no_metric = false;
  std::string scale_dir, scale_recording;
  double distance = 0;
  std::vector<std::string> from, to;  // NAME@X,Y each
};

mapping::BoardSpec BoardOf(const MapArgs& args) {
  if (args.square <= 0) throw CommandError("--board needs --square, the side of one of its squares in metres", 2);
  mapping::BoardSpec spec;
  spec.inner_corners = *ParseFrameSize(args.board);  // checked by --board's validator
  spec.square = args.square;
  spec.on_floor = !args.board_off_floor;
  return spec;
}

// "000012.png@312.5,220" → the keyframe's name and the pixel.
std::vector<mapping::PointSighting> ParseSightings(const std::vector<std::string>& texts, const char* flag) {
  std::vector<mapping::PointSighting> sightings;
  for (const std::string& text : texts) {
    const size_t at = text.rfind('@');
    double x = 0, y = 0;
    char tail = 0;
    if (at == std::string::npos || at == 0 || std::sscanf(text.c_str() + at + 1, "%lf,%lf%c", &x, &y, &tail) != 2 ||
        !std::isfinite(x) || !std::isfinite(y)) {
      throw CommandError(std::string(flag) + " '" + text + "' must be KEYFRAME@X,Y, e.g. 000012.png@312.5,220", 2);
    }
    sightings.push_back({text.substr(0, at), {x, y}});
  }
  if (sightings.size() < 2) throw CommandError(std::string(flag) + " needs the point's pixel in at least two keyframes", 2);
  return sightings;
}

// What `map info` and the end of `map` and `map scale` say about the frame.
std::string DescribeFrame(const map::MapFrame& f) {
  if (!f.metric()) return "COLMAP's own (arbitrary units, no up): 'arview map scale' makes it metric";
  std::string text = std::string("metres, +z up, from ") + map::ToString(f.scale_source) + " (likely scale error " +
                     Fixed(100 * f.scale_error, f.scale_error < 0.01 ? 2 : 1) + "%): " + f.how;
  return text;
}


void RunMap(const MapArgs& args) {
  if (args.recordings.empty()) throw CommandError("map: the recording folder is required (arview map <recording> --out <map-dir>)", 2);
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
  options.gap_retry_angle_deg = args.gap_retry_angle;
  options.leaf_size = args.leaf_size;
  options.leaf_overlap = args.leaf_overlap;
  options.cross_rooms.neighbours = args.cross_room_neighbours;
  options.leaves_within_rooms = args.leaves_within_rooms;
  options.slurm.partition = args.slurm_partition;
  options.slurm.cpus_per_task = args.slurm_cpus;
  options.slurm.time_limit_minutes = args.slurm_time_limit;
  options.slurm_chunk = args.slurm_chunk;
  if (args.engine == "slurm" && args.leaf_size == 0 && args.slurm_chunk == 0)
    throw CommandError("map: --engine slurm runs stages as jobs: give --leaf-size (the mapping in leaves) or "
                       "--slurm-chunk (extraction and matching), or both", 2);
  if (args.slurm_chunk > 0 && args.engine != "slurm")
    throw CommandError("map: --slurm-chunk makes Slurm jobs: it needs --engine slurm", 2);
  // The jobs' settings mean nothing without jobs: refused rather than ignored.
  for (const auto& [flag, given] : {std::pair{"--slurm-partition", !args.slurm_partition.empty()},
                                    std::pair{"--slurm-cpus", args.slurm_cpus > 0},
                                    std::pair{"--slurm-time-limit", args.slurm_time_limit > 0}}) {
    if (given && args.engine != "slurm")
      throw CommandError(std::string("map: ") + flag + " sets the Slurm jobs: it needs --engine slurm", 2);
  }
  if (!args.board.empty()) {
    if (args.no_metric) throw CommandError("map: --board and --no-metric exclude each other", 2);
    options.scale.from = mapping::ScaleFrom::kBoard;
    options.scale.board = BoardOf(args);
  } else if (!args.no_metric) {
    options.scale.from = mapping::ScaleFrom::kCameraHeight;
  }
  const ScopedSignalCancellation signals;
  options.cancel = signals.token();
  ProgressBar bar;
  const mapping::MapBuildCallbacks callbacks = ConsoleCallbacks(bar, signals.token());
  try {
    options.matcher = mapping::ParseMatcherKind(args.matcher);
    options.match_engine = mapping::ParseMatchEngine(args.match_engine);
    options.engine = mapping::ParseMapEngine(args.engine);
    std::vector<mapping::VenueRoom> rooms;
    const recordings::Recording recording =
        args.recordings.size() == 1
            ? recordings::LoadRecording(args.recordings.front())
            : mapping::VenueRecording({args.recordings.begin(), args.recordings.end()}, args.out, &rooms);
    options.rooms = rooms;
    const auto result = mapping::BuildMap(recording, args.out, options, callbacks);
    if (!rooms.empty()) {
      mapping::WriteVenueFile(rooms, result.map, args.out);
    } else {
      std::error_code ec;  // a folder that held a venue's map holds one recording's now
      fs::remove(fs::path(args.out) / mapping::kVenueFileName, ec);
    }
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
    if (const auto venue = mapping::ReadVenueFile(args.out))
      for (const auto& room : *venue) std::cout << "room " << mapping::DescribeRoom(room) << "\n";
    std::cout << "check: " << mapping::DescribeMapCheck(result.check) << "\n";
    std::cout << "frame: " << DescribeFrame(result.map.frame) << "\n";
    std::cout << "wrote " << args.out << "/{" << map::kMapFileName << ", " << mapping::kMapCheckFileName
              << ", keyframes.txt, map.png, database.db}, COLMAP model " << result.model_dir.string() << "\n";
    if (!result.scale_failure.empty()) {
      throw CommandError("the map was written, but not made metric from the board: " + result.scale_failure +
                         ". Its scale is " + (result.map.frame.metric() ? "the camera-height estimate" : "COLMAP's") +
                         "; 'arview map scale " + args.out + " ...' sets it once the board is usable");
    }
  } catch (const mapping::ColmapStageError& e) {
    bar.Finish();
    std::cerr << "last lines of COLMAP's output (" << e.log.string() << "):\n";
    for (const auto& line : e.log_tail) std::cerr << "  | " << line << "\n";
    throw;  // main() says its line
  } catch (const CancelledError&) {
    bar.Finish();
    throw;  // its message says which stage stopped and what was kept
  }
}

void RunScale(const MapArgs& args) {
  mapping::ScaleRequest request;
  if (!args.board.empty()) {
    if (args.distance > 0) throw CommandError("map scale: give --board or --distance, not both", 2);
    request.from = mapping::ScaleFrom::kBoard;
    request.board = BoardOf(args);
  } else if (args.distance > 0) {
    request.from = mapping::ScaleFrom::kKnownDistance;
    request.distance_m = args.distance;
    request.point_a = ParseSightings(args.from, "--from");
    request.point_b = ParseSightings(args.to, "--to");
  } else {
    throw CommandError("map scale: say where the scale comes from: --board CxR --square M, or --distance M --from "
                       "KEYFRAME@X,Y KEYFRAME@X,Y --to KEYFRAME@X,Y KEYFRAME@X,Y",
                       2);
  }
  mapping::MapBuildOptions options;
  options.colmap = args.colmap;
  const ScopedSignalCancellation signals;
  options.cancel = signals.token();
  ProgressBar bar;
  mapping::MapBuildCallbacks callbacks;  // progress only: the map's own check warnings are not news here
  callbacks.progress = ConsoleCallbacks(bar, signals.token()).progress;
  try {
    std::optional<recordings::Recording> recording;
    if (!args.scale_recording.empty()) recording = recordings::LoadRecording(args.scale_recording);
    const map::Map map = mapping::ScaleMapFolder(args.scale_dir, recording ? &*recording : nullptr, request, options, callbacks);
    bar.Finish();
    std::cout << "frame: " << DescribeFrame(map.frame) << "\n"
              << "rewrote " << args.scale_dir << "/{" << map::kMapFileName << ", " << mapping::kMapCheckFileName
              << ", keyframes.txt, map.png} and the COLMAP model in metres\n";
  } catch (const mapping::ColmapStageError&) {
    throw;  // a MapError whose own line main() says, without the map's name before it
  } catch (const map::MapError& e) {
    throw CommandError(args.scale_dir + ": " + e.what() + " (the map was not changed)");
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
  std::cout << "frame:               " << DescribeFrame(map.frame) << "\n";
  const fs::path folder = fs::is_directory(dir, ec) ? fs::path(dir) : fs::path(dir).parent_path();
  if (const auto check = mapping::ReadMapCheck(folder / mapping::kMapCheckFileName)) {
    std::cout << "check:               " << mapping::DescribeMapCheck(*check) << "\n";
    for (const auto& warning : check->warnings) std::cout << "warning:             the map " << warning << "\n";
    if (!check->flagged()) std::cout << "                     (nothing flagged)\n";
  } else {
    std::cout << "check:               not recorded (" << mapping::kMapCheckFileName
              << " is written by arview map since issue 17)\n";
  }
  const auto venue = mapping::ReadVenueFile(folder);
  if (!map.rooms.empty()) {
    const std::string frames_from = venue ? "; their frames from " + std::string(mapping::kVenueFileName) : "";
    std::cout << "rooms:               " << map.rooms.size() << " (the map file's" << frames_from << ")\n";
    for (const std::string& line : mapping::DescribeMapRooms(map, venue ? *venue : std::vector<mapping::VenueRoom>{}))
      std::cout << "                     " << line << "\n";
  } else if (venue) {
    std::cout << "rooms:               " << venue->size() << " (" << mapping::kVenueFileName
              << "; the map file names none: it is older, 'arview map' again names them)\n";
    for (const auto& room : *venue) std::cout << "                     " << mapping::DescribeRoom(room) << "\n";
  }
  if (const auto why = map::DegeneratePoints(map)) {
    std::cout << "warning:             the map's points cannot hold a floor ('arview place' refuses the map): " << *why
              << "\n";
  }
}

}  // namespace

void AddMapCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("map", "Build the map of a scene from a recording with COLMAP ('map info' describes one)");
  auto args = std::make_shared<MapArgs>();
  cmd->add_option("recording", args->recordings,
                  "Recording folder (see 'arview import'); several: a venue, its recordings (rooms) mapped as one, "
                  "named in the map (venue.json, 'arview map info')");
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
  cmd->add_option("--gap-retry-angle", args->gap_retry_angle,
                  "When COLMAP leaves out a stretch of 3 or more consecutive frames (the walk after a fast turn), "
                  "run its mapper again on the same matches with the triangulation angles lowered from 1.5 to this "
                  "many degrees, and keep the model that registers more frames (0: no retry)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.4));
  cmd->add_option("--cross-room-neighbours", args->cross_room_neighbours,
                  "A venue matched sequentially: each room's frames among themselves, and each frame with this many "
                  "frames of the other rooms that share most of its SIFT descriptors (0: the rooms' frames as one "
                  "sequence, room after room, for recordings walked one into the next)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--leaf-size", args->leaf_size,
                  "Map in parts: with more frames than this, cut the match graph (METIS on the inliers) into leaves "
                  "of at most this many frames, map each alone and merge them (0: one mapper over every frame)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--leaf-overlap", args->leaf_overlap,
                  "Frames added to each leaf from its neighbours, the most strongly matched first, for the merge")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  cmd->add_flag("--leaves-within-rooms", args->leaves_within_rooms,
                "A venue mapped in leaves: cut the leaves within each room (a room under 10 frames goes with the room "
                "it matched most), not by the match graph alone");
  cmd->add_option("--engine", args->engine,
                  "Where the leaves are mapped (and with --slurm-chunk, extraction and matching run): local (one after "
                  "another here) or slurm (job arrays and a merge job through sbatch, a failed job submitted once "
                  "more; the map folder must be on a filesystem every node sees)")
      ->capture_default_str()
      ->check(CLI::IsMember({"local", "slurm"}));
  cmd->add_option("--slurm-chunk", args->slurm_chunk,
                  "With --engine slurm: feature extraction and matching as Slurm jobs of about this many frames each, "
                  "their databases merged here (0: both run here)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--slurm-partition", args->slurm_partition, "The Slurm partition of the jobs (default: the cluster's)");
  cmd->add_option("--slurm-cpus", args->slurm_cpus, "CPUs each Slurm job asks for (0: --threads)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--slurm-time-limit", args->slurm_time_limit,
                  "Each Slurm job's wall-time limit in minutes (sbatch --time): a job past it (a hung COLMAP) ends and "
                  "is submitted once more (0: the partition's default)")
      ->capture_default_str()
      ->check(CLI::Range(0, 525600));

  auto* info = cmd->add_subcommand("info", "Describe a map: frames, points, track length, reprojection error, load time");
  info->add_option("map-dir", args->info_dir, "Map directory (or its map.arvmap)")->required();
  info->add_flag("--recheck", args->info_recheck,
                 "Run the map's self-check again from the COLMAP model and database in its folder and rewrite "
                 "check.json (maps built before a check existed)");
  info->callback([args] { RunInfo(args->info_dir, args->info_recheck); });

  const auto add_board = [args](CLI::App* c, const std::string& what) {
    c->add_option("--board", args->board,
                  "A printed chessboard seen in the frames, its inner corners COLUMNSxROWS (e.g. 9x6 for 10 x 7 "
                  "squares): " + what)
        ->check(BoardSizeCheck());
    c->add_option("--square", args->square, "The board's square side, metres (with --board)")->check(CLI::Range(1e-4, 10.0));
    c->add_flag("--board-off-floor", args->board_off_floor,
                "The board is not lying on the floor (on a wall, a table's edge): it gives the scale only, up comes "
                "from the floor");
  };
  add_board(cmd, "the map is made metric from it, with up from its normal when it lies on the floor");
  cmd->add_flag("--no-metric", args->no_metric,
                "Keep COLMAP's arbitrary units and orientation (by default a map without --board is scaled by the "
                "estimate of a 1.45 m camera height over the floor, and stood upright on the floor)");
  auto* scale = cmd->add_subcommand(
      "scale", "Make a map metric and upright afterwards: from a board seen in its keyframes, or a known distance");
  scale->add_option("map-dir", args->scale_dir, "Map directory")->required();
  scale->add_option("recording", args->scale_recording,
                    "The recording the map was built from (a still-image map's keyframe images are its frames; a "
                    "video map keeps its own)");
  add_board(scale, "the map is made metric from it");
  scale->add_option("--distance", args->distance, "Metres between the two points given by --from and --to")
      ->check(CLI::Range(1e-4, 1e4));
  scale->add_option("--from", args->from, "One end: KEYFRAME@X,Y in two or more keyframes (names as in keyframes.txt "
                                          "or images/), e.g. 000012.png@312.5,220 000040.png@280,231")
      ->expected(2, 16);
  scale->add_option("--to", args->to, "The other end, the same way")->expected(2, 16);
  scale->add_option("--colmap", args->colmap, "The COLMAP executable")->capture_default_str();
  scale->callback([args] { RunScale(*args); });
  AddMapExtendCommand(*cmd);
  cmd->callback([args, cmd] {
    if (!cmd->get_subcommands().empty()) return;  // `map info`, `map scale`, `map extend`: their own callbacks ran
    RunMap(*args);
  });
}

}  // namespace arview::app
