#include "app/cli/session_flags.h"

#include "app/cli/output_flags.h"
#include "app/placement/scene_lighting.h"
#include "map/map_file.h"
#include "map/map_rooms.h"
#include "base/cache_folder.h"
#include "render/hmd.h"
#include "render/offscreen.h"
#include "render/prt_cache.h"

namespace arview::app {

namespace {

// The flags' names for SessionOptions::Check()'s messages: the path of each field they set.
OptionNames SessionFlagNames() {
  return OptionNames({{"compositor.stereo_character", "--stereo-character"},
                      {"compositor.hmd", "--hmd or --hmd-profile"},
                      {"compositor.ipd_m", "--ipd"},
                      {"fade.hold_seconds", "--hold"},
                      {"fade.fade_seconds", "--fade"},
                      {"tracker.tracking.background", "--tracking-worker"},
                      {"tracker.tracking.prefetch_below", "--prefetch-below"},
                      {"tracker.tracking.align_max_seconds", "--align-max-seconds"}});
}

}  // namespace

void AddAlignMaxSecondsOption(CLI::App* cmd, double& seconds) {
  cmd->add_option("--align-max-seconds", seconds,
                  "Whip-pans: a frame no feature step can pose takes its rotation from image alignment with the "
                  "frame before, for at most this long after the last pose from features (0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
}

void AddRoomOption(CLI::App* cmd, std::string& room) {
  cmd->add_option("--room", room,
                  "Of a venue's map (several recordings mapped as one, 'arview map info' lists its rooms): load "
                  "only this room and the rooms next to it (those whose keyframes see 2 % of its points, as 'arview map "
                  "info' lists them), "
                  "not the whole venue");
}

map::Map LoadSessionMap(const std::string& map_dir, const std::string& room) {
  map::Map map = map::LoadMap(map_dir);
  if (room.empty()) return map;
  int index = -1;
  try {
    index = map::RoomIndex(map, room);
  } catch (const map::MapError& e) {
    throw CommandError("--room " + room + ": " + map_dir + ": " + e.what(), 2);
  }
  const std::vector<int> rooms = map::RoomWithNeighbours(map, index);
  map::Map part = map::RoomsPart(map, rooms);
  std::string names;
  for (const int r : rooms) names += (names.empty() ? "" : r == rooms.back() ? " and " : ", ") + map.rooms[r];
  std::fprintf(stderr, "note: --room %s: loaded %s: %zu of the map's %zu keyframes, %zu of its %zu points\n",
               room.c_str(), names.c_str(), part.keyframes.size(), map.keyframes.size(), part.points.size(),
               map.points.size());
  return part;
}

void AddSessionFlags(CLI::App* cmd, SessionFlags& f) {
  cmd->add_option("--scene", f.scene,
                  "Scene file (see 'arview place'); without it the built-in figure stands on the map's floor in front "
                  "of the first localized view, and the line saying where gives the 'arview place' command that keeps it");
  cmd->add_flag("--no-figure", f.no_figure, "Without --scene: no character, only the video tracked");
  AddRoomOption(cmd, f.room);
  cmd->add_option("--trajectory", f.trajectory, "Also write the tracked poses (TUM, camera-to-world)")
      ->check(OutputFileCheck());
  cmd->add_option("--stats", f.stats, "Also write per-stage timings and per-frame tracking as JSON")
      ->check(OutputFileCheck());
  cmd->add_flag("--hmd", f.hmd,
                "Head-mounted display: one half per eye, the same video in both (one camera), the character "
                "rendered once (biocular; see --stereo-character)");
  cmd->add_option("--hmd-profile", f.hmd_profile,
                  "Headset profile (YAML: panel, eye_fov_deg, lens_centre, distortion; docs/examples/hmd-cardboard.yaml): "
                  "the eyes' views placed on its panel and pre-distorted for its lenses; implies --hmd");
  cmd->add_option("--window-output", f.window_output,
                  "With --out window: the display output (xrandr's name, e.g. HDMI-1) whose top-left corner the "
                  "window opens at: a headset's panel");
  cmd->add_flag("--fullscreen", f.fullscreen, "With --out window: ask the window manager for a fullscreen window");
  cmd->add_flag("--stereo-character", f.stereo_character,
                "With --hmd: render the character once per eye, --ipd apart (true depth only on a metric map)");
  cmd->add_option("--ipd", f.ipd, "Interpupillary distance for --stereo-character, in map units (metres for metric maps)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--hud", f.hud, "Draw the view-sphere overlay: key viewpoints coloured by weight, the current viewpoint");
  AddGlFlags(cmd, f.gl);
  cmd->add_option("--tracking-worker", f.tracking_worker,
                  "on: guided matching's SIFT and relocalization run on a worker thread and the tracking thread "
                  "never waits for them (frames meanwhile are posed on optical flow, or shown with the video "
                  "alone while relocalising); off: every step in line, results independent of timing; auto: on "
                  "for a live source (run, replay --paced)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_option("--prefetch-below", f.prefetch_below,
                  "Extract guided matching's SIFT ahead, on the worker thread, when fewer flow tracks survive; 0: "
                  "off (default: " + std::to_string(tracker::kBackgroundPrefetchBelow) +
                      " with the tracking worker, else off)")
      ->check(CLI::Range(0, 100000));
  AddAlignMaxSecondsOption(cmd, f.align_max_seconds);
  cmd->add_option("--aa", f.aa, "Antialiasing of the character: msaa (4x multisampling) or none (cheaper on a CPU renderer)")
      ->capture_default_str()
      ->check(CLI::IsMember({"msaa", "none"}));
  cmd->add_option("--lighting", f.lighting, "auto (prt when the scene has a .light.yml), fixed, sh or prt")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "fixed", "sh", "prt"}));
  cmd->add_option("--light", f.light, "Room light file (default: the scene's <scene>.light.yml)");
  cmd->add_option("--hold", f.hold, "Seconds the character holds its last view after tracking is lost")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  cmd->add_option("--fade", f.fade, "Seconds to fade to the idle clip, and back after relocalization")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
}

void ApplySessionFlags(const SessionFlags& f, bool live_source, SessionOptions& o) {
  if (f.no_figure && !f.scene.empty()) throw CommandError("--no-figure is for a session without --scene");
  o.scene_file = f.scene;
  o.trajectory_out = f.trajectory;
  o.stats_out = f.stats;
  o.compositor.gl = ToOffscreenOptions(f.gl);
  o.compositor.hmd = f.hmd || !f.hmd_profile.empty();
  if (!f.hmd_profile.empty()) o.compositor.hmd_profile = render::LoadHmdProfile(f.hmd_profile);
  o.compositor.stereo_character = f.stereo_character;
  o.compositor.ipd_m = f.ipd;
  o.compositor.hud = f.hud;
  const OptionNames names = SessionFlagNames();
  o.compositor.Check(names.Nested("compositor"));
  o.window = {f.window_output, f.fullscreen};
  const bool worker = f.tracking_worker == "on" || (f.tracking_worker == "auto" && live_source);
  o.tracker.tracking.background = worker;
  o.tracker.tracking.prefetch_below = f.prefetch_below >= 0 ? f.prefetch_below : worker ? tracker::kBackgroundPrefetchBelow : 0;
  o.tracker.tracking.align_max_seconds = f.align_max_seconds;
  o.tracker.Check(names.Nested("tracker"));  // --prefetch-below 0 with the worker
  o.compositor.ar.antialiasing = render::ParseAntialiasing(f.aa);
  o.fade = {f.hold, f.fade};
  o.fade.Check(names.Nested("fade"));
  const SceneLighting lighting = ResolveSceneLighting(f.scene, f.lighting, f.light);
  o.compositor.ar.lighting = lighting.mode;
  o.compositor.ar.prt_cache_folder = render::DefaultPrtCacheFolder();
  o.tracker.index_cache_folder = CacheFolder("descriptor-index");
  o.compositor.room_light = lighting.light;
}

}  // namespace arview::app
