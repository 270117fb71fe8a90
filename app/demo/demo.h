#pragma once
// `arview demo`: everything on the embedded default, with no camera and no downloads.
//
// The project renders its own room and a hand-held walk of two laps round the spot where the
// character will stand (exact ground truth), maps the first lap with COLMAP, stands the
// project's own humanoid (builtin:figure, figure/) on that spot facing where the viewer will
// come close, with eight look-at keys, replays the second lap — which circles the character,
// passes behind it, glances away fast once and comes close once — through the whole pipeline
// (tracking, view-adaptive animation, rendering, compositing) into an MP4, judges the tracking
// against the ground truth, measures what a viewer sees (the character in the picture, its head
// toward the camera) and writes a contact sheet of the video. During the replay a visitor's two
// questions (a WAV the demo synthesizes) are heard and answered by a built-in dialogue
// (app/demo/demo_exchange.h).


#include <string>

#include "render/offscreen.h"

namespace arview::app {

struct DemoOptions {
  std::string out;                   // the augmented video; empty: <work>/demo.mp4
  std::string work = "arview-demo";  // the recordings, the map and the reports (reused by a re-run)
  int frames = 1340;  // two laps of the room path (one lap: 22.2 s at 30 fps)
  int map_every = 7;
  std::string character = "builtin:figure";
  double height = 1.72;  // metres
  render::OffscreenOptions gl;  // auto, 1 llvmpipe thread (the tracker needs the other core)
  bool hmd = false;
  bool no_hud = false;
  double greet_within = 1.4;  // metres
  int frame_width = 640, frame_height = 480;  // the walk's frame size (rendered, mapped and replayed at it)
  std::string aa = "msaa";
};

// The demo's seven steps, printed as they go; the outputs go to options.work (and options.out).
// Throws Error for a bad character or a failed step, CancelledError on Ctrl-C / SIGTERM.
void RunDemo(const DemoOptions& options);

}  // namespace arview::app
