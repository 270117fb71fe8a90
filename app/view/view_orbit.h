#pragma once
// The scripted orbit of `arview view --orbit <spec> --out orbit.mp4`:
//   "azimuth=0..360,elevation=15,distance=2.5,seconds=8"
// Each field is a number or a `from..to` range swept linearly over the orbit; fields may be left
// out (azimuth 0..360, elevation and distance: the default view's, seconds 8). Azimuth and
// elevation are degrees in the character's frame (as key viewpoints), distance is from the
// orbit's target (the middle of the character's height) in map units.

#include <optional>
#include <string>

#include "app/view/view_camera.h"

namespace arview::app {

struct Range {
  double from = 0, to = 0;
  double At(double u) const { return from + (to - from) * u; }
};

struct OrbitSpec {
  Range azimuth_deg{0, 360};
  std::optional<Range> elevation_deg, distance;  // nothing: the default view's
  double seconds = 8;
};

// Throws std::runtime_error "--orbit: ..." naming the bad field.
OrbitSpec ParseOrbitSpec(const std::string& text);

// The camera at fraction u ∈ [0, 1] of the orbit, starting from `home` for what the spec leaves out.
OrbitState OrbitAt(const OrbitSpec& spec, const OrbitState& home, double u);

}  // namespace arview::app
