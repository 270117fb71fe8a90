#pragma once
// `arview synth venue`: the walk through a venue of rooms joined by doors (venue_layout.h)
// rendered as one recording with exact ground truth, and the room each frame is in.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "render/offscreen.h"
#include "synth/venue_layout.h"

namespace arview::synth {

struct SynthVenueOptions {
  std::filesystem::path out;
  VenueLayout layout;
  int frames = 720;              // the whole walk, at fps
  double fps = 30.0;
  uint64_t seed = 1;             // the textures
  int width = 640, height = 480;
  // Only these frames of the walk are rendered and listed (recordings::ParseFrameSpec), each
  // exactly as in the whole recording: one room's frames as a recording of its own.
  std::string frames_subset;
  int samples = 4;               // MSAA samples
  bool overwrite = false;        // replace a recording already in `out`
  render::OffscreenOptions gl;
};

// Renders and writes the recording: frames/NNNNNN.png, frames.txt, camera.yaml (RoomCamera at
// the size), groundtruth.txt (TUM, camera-to-world) and rooms.txt (each frame's timestamp and the
// room its camera is in: `0.033333 room-1`). Throws RenderError naming a bad option or the file
// it could not write. Returns the frames written.
int SynthesizeVenue(const SynthVenueOptions& options, const std::function<void(int, int)>& progress = nullptr);

}  // namespace arview::synth
