#include "app/cli/camera_flags.h"

#include <charconv>
#include <cstdint>

#include "app/cli/numeric_flags.h"

namespace arview::app {

namespace {

bool IsWholeNumber(const std::string& text) {
  int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return !text.empty() && ec == std::errc() && ptr == end;
}

CLI::Validator WordOrNumber(std::vector<std::string> words, const std::string& description) {
  auto check = [words, description](std::string& text) -> std::string {
    for (const std::string& w : words) {
      if (text == w) return "";
    }
    if (IsWholeNumber(text)) return "";
    return "'" + text + "' is not " + description;
  };
  return CLI::Validator(check, description);
}

}  // namespace

CLI::Validator FocusCheck() {
  return WordOrNumber({"lock", "auto", "keep"}, "lock, auto, keep or a whole number (the focus position)");
}

CLI::Validator ExposureCheck() {
  return WordOrNumber({"auto", "lock"}, "auto, lock or a whole number (the exposure time in the camera's units)");
}

void AddCameraFlags(CLI::App* cmd, CameraFlags& flags, const std::string& size_help) {
  cmd->add_option("--size", flags.size, "Frame size to ask the camera for, WIDTHxHEIGHT (" + size_help + ")")
      ->check(FrameSizeCheck({16, 16}, {7680, 4320}));
  cmd->add_option("--fps", flags.fps, "Frames per second to ask for (0: the highest the camera offers at the size)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--format", flags.format,
                  "Pixel format: auto (YUYV where it reaches the rate at the size, else MJPEG), yuyv or mjpeg")
      ->check(CLI::IsMember({"auto", "yuyv", "mjpeg"}))
      ->capture_default_str();
  cmd->add_option("--focus", flags.focus,
                  "lock (auto-focus off where it is: keeps a calibration valid), auto, keep (as the camera is) or a "
                  "focus position (default: the calibration's focus_absolute where it has one, else lock)")
      ->check(FocusCheck());
  cmd->add_option("--exposure", flags.exposure,
                  "auto, lock (manual at the current exposure time: dim light cannot lower the frame rate) or an "
                  "exposure time in the camera's units")
      ->check(ExposureCheck())
      ->capture_default_str();
}

void ApplyCameraFlags(const CameraFlags& flags, recordings::V4l2Options& options) {
  options.fps = flags.fps;
  options.format = flags.format;
  options.focus = flags.focus.empty() ? "lock" : flags.focus;
  options.exposure = flags.exposure;
}

std::string SessionFocus(const CameraFlags& flags, const calib::Camera& calibration) {
  if (!flags.focus.empty()) return flags.focus;
  return calibration.focus ? std::to_string(*calibration.focus) : "lock";
}

std::string FocusMismatch(const recordings::V4l2Source& source, const calib::Camera& calibration,
                          const std::string& whose) {
  if (!calibration.focus) return "";
  const std::string wanted = std::to_string(*calibration.focus);
  if (!source.focus_held()) {
    return source.Name() + " focuses automatically, but " + whose + " was calibrated at focus " + wanted +
           ": the focal length changes under it (--focus " + wanted + " holds it there)";
  }
  if (source.focus_position() && *source.focus_position() != *calibration.focus) {
    return source.Name() + " is focused at " + std::to_string(*source.focus_position()) + ", but " + whose +
           " was calibrated at focus " + wanted + ": another focal length (--focus " + wanted + " holds it there)";
  }
  return "";
}

}  // namespace arview::app
