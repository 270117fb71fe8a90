#pragma once
// Light that changes while the synthetic room is filmed (`arview synth room --lamp-off`,
// `--lamp-on`, `--sun`, `--auto-exposure`). The room's light is baked into its surfaces
// (synth_room.h), so a change is a per-pixel gain on the rendered frame:
//   - the lamp: the room's light; switched off, every surface gets a quarter of it (−2 EV from
//     one frame to the next), switched on, all of it again;
//   - the sun through the window (SynthLighting::kWindow): a patch of direct sunlight cast
//     through the window's opening onto the floor, walls and boxes (+1 EV where it falls, the
//     window's bars in shadow), moving as the sun's azimuth sweeps 60° over the recording;
//   - the camera's auto-exposure: after a change of the lamp it re-exposes toward the old
//     brightness in steps of 1/3 EV every 4 frames, starting 0.3 s after the change (frames
//     clipped white while it steps down after the lamp comes back on).

#include <opencv2/core.hpp>

#include "calib/camera.h"
#include "calib/pose.h"

namespace arview::synth {

struct LightChanges {
  double lamp_off_s = -1;       // recording time the lamp goes off; < 0: it never does
  double lamp_on_s = -1;        // and back on (after lamp_off_s); < 0: it stays off
  bool sun = false;             // the window's sunlight moving over the room
  bool auto_exposure = false;   // the camera re-exposes after the lamp's changes
  double duration_s = 0;        // the recording's length: the sun's sweep spans it

  bool any() const { return lamp_off_s >= 0 || sun || auto_exposure; }
};

inline constexpr double kLampOffGain = 0.25;  // −2 EV

// The lamp's share of its light at time t: 1 or kLampOffGain.
double LampGain(const LightChanges& changes, double t);
// The exposure's gain at frame `frame` (recording time frame / fps): 2^(EV the camera added).
double ExposureGain(const LightChanges& changes, double fps, int frame);

// Applies the changes to a frame rendered from `pose` at recording time t (frame `frame`):
// `walkers`, when not empty, marks pixels of people in front (8-bit, non-zero), which the sun's
// patch on the surfaces behind them does not light.
void ApplyLightChanges(cv::Mat& image, const LightChanges& changes, const calib::Camera& camera, const calib::Pose& pose,
                       double fps, int frame, const cv::Mat& walkers = {});

}  // namespace arview::synth
