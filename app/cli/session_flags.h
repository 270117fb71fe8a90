#pragma once
// The flags `arview replay` and `arview run` share: what is drawn, how, and where the results go.

#include <string>

#include "app/session/ar_session.h"
#include "app/cli/commands.h"
#include "app/cli/gl_flags.h"

namespace arview::app {

struct SessionFlags {
  std::string scene, trajectory, stats, aa = "msaa";
  GlFlags gl;  // 1 llvmpipe thread: the tracker needs the other core
  std::string lighting = "auto", light;  // see app/placement/scene_lighting.h
  bool hmd = false, hud = false, stereo_character = false;
  std::string hmd_profile, window_output;
  bool fullscreen = false;
  bool no_figure = false;  // without --scene: no built-in figure (FirstRunFigure)
  // The defaults are the options structs' own.
  double ipd = CompositorOptions{}.ipd_m, hold = FadeOptions{}.hold_seconds, fade = FadeOptions{}.fade_seconds;
  // tracker::TrackingOptions::prefetch_below; -1: tracker::kBackgroundPrefetchBelow with the
  // tracking worker, else 0 (off)
  int prefetch_below = -1;
  std::string tracking_worker = "auto";  // auto (on for a live source), on, off
  double align_max_seconds = tracker::TrackingOptions{}.align_max_seconds;
  std::string room;  // --room: a venue's room, loaded with its neighbours only
};

void AddSessionFlags(CLI::App* cmd, SessionFlags& flags);
// --room NAME (`track`, `replay`, `run`): of a venue's map, load that room and the rooms next to it only.
void AddRoomOption(CLI::App* cmd, std::string& room);
// The map in `map_dir`; with `room` (--room) that room and its neighbours only (map/map_rooms.h),
// a note on stderr saying which rooms and how much of the map. An unknown room is a
// CommandError naming the rooms there are.
map::Map LoadSessionMap(const std::string& map_dir, const std::string& room);
// --align-max-seconds (tracker::TrackingOptions::align_max_seconds), shared with `arview track`.
void AddAlignMaxSecondsOption(CLI::App* cmd, double& seconds);
// Fills the session options these flags control and checks them (SessionOptions::Check: an
// OptionError naming the flag, e.g. --stereo-character without --hmd; a RenderError on a bad --gl
// value). live_source: frames
// come at the camera's rate whether or not the pipeline keeps up (`run`, `replay --paced`), which
// turns the tracking worker on under --tracking-worker auto.
void ApplySessionFlags(const SessionFlags& flags, bool live_source, SessionOptions& options);

}  // namespace arview::app
