#pragma once
// The camera set-up flags that `arview run` and `arview record` share: --size, --fps, --format,
// --focus, --exposure (recordings/v4l2_source.h says what each does to the camera).

#include <CLI/CLI.hpp>

#include <string>

#include "recordings/v4l2_source.h"

namespace arview::app {

struct CameraFlags {
  std::string size;  // WIDTHxHEIGHT; empty: the command's own default
  double fps = 0;    // 0: the highest the camera offers at the size
  std::string format = "auto";
  std::string focus = "lock";
  std::string exposure = "auto";
};

// Adds the flags to `cmd`; `size_help` says what --size defaults to for that command.
void AddCameraFlags(CLI::App* cmd, CameraFlags& flags, const std::string& size_help);

// Fills the rate, format, focus and exposure of `options` (the size is the command's to choose).
void ApplyCameraFlags(const CameraFlags& flags, recordings::V4l2Options& options);

// "lock", "auto", "keep" or a whole number for --focus; "auto", "lock" or a whole number for
// --exposure: CLI11 validators whose message names the flag.
CLI::Validator FocusCheck();
CLI::Validator ExposureCheck();

}  // namespace arview::app
