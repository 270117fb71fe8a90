#include "app/view/view_orbit.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace arview::app {

namespace {

// `value` is the whole field value, for the message.
double Number(const std::string& text, const std::string& field, const std::string& value) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size() || !std::isfinite(v)) {
    throw std::runtime_error("--orbit: " + field + "=" + value + " is not a number or a from..to range");
  }
  return v;
}

Range ParseRange(const std::string& text, const std::string& field) {
  const size_t dots = text.find("..");
  if (dots == std::string::npos) {
    const double v = Number(text, field, text);
    return {v, v};
  }
  return {Number(text.substr(0, dots), field, text), Number(text.substr(dots + 2), field, text)};
}

}  // namespace

OrbitSpec ParseOrbitSpec(const std::string& text) {
  OrbitSpec spec;
  if (text.empty()) throw std::runtime_error("--orbit: empty (e.g. azimuth=0..360,elevation=15,seconds=8)");
  size_t start = 0;
  while (start <= text.size()) {
    size_t comma = text.find(',', start);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = text.substr(start, comma - start);
    const size_t eq = item.find('=');
    if (eq == std::string::npos) {
      throw std::runtime_error("--orbit: '" + item + "' is not field=value (fields: azimuth, elevation, distance, seconds)");
    }
    const std::string field = item.substr(0, eq), value = item.substr(eq + 1);
    if (field == "azimuth") {
      spec.azimuth_deg = ParseRange(value, field);
    } else if (field == "elevation") {
      spec.elevation_deg = ParseRange(value, field);
      for (double e : {spec.elevation_deg->from, spec.elevation_deg->to}) {
        if (std::abs(e) > OrbitCamera::kMaxElevationDeg) throw std::runtime_error("--orbit: elevation must be within ±89 deg");
      }
    } else if (field == "distance") {
      spec.distance = ParseRange(value, field);
      if (!(spec.distance->from > 0 && spec.distance->to > 0)) throw std::runtime_error("--orbit: distance must be > 0");
    } else if (field == "seconds") {
      spec.seconds = Number(value, field, value);
      if (!(spec.seconds > 0 && spec.seconds <= 3600)) throw std::runtime_error("--orbit: seconds must be in (0, 3600]");
    } else {
      throw std::runtime_error("--orbit: unknown field '" + field + "' (fields: azimuth, elevation, distance, seconds)");
    }
    start = comma + 1;
  }
  return spec;
}

OrbitState OrbitAt(const OrbitSpec& spec, const OrbitState& home, double u) {
  OrbitState s = home;
  s.azimuth_deg = spec.azimuth_deg.At(u);
  if (spec.elevation_deg) s.elevation_deg = spec.elevation_deg->At(u);
  if (spec.distance) s.distance = spec.distance->At(u);
  return s;
}

}  // namespace arview::app
