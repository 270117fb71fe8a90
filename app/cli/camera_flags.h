#pragma once
// The camera set-up flags that `arview run` and `arview record` share: --size, --fps, --format,
// --focus, --exposure (recordings/v4l2_source.h says what each does to the camera).

#include <CLI/CLI.hpp>

#include <string>

#include "calib/camera.h"
#include "recordings/v4l2_source.h"

namespace arview::app {

struct CameraFlags {
  std::string size;  // WIDTHxHEIGHT; empty: the command's own default
  double fps = 0;    // 0: the highest the camera offers at the size
  std::string format = "auto";
  std::string focus;  // empty: the calibration's focus where it says one, else lock
  std::string exposure = "auto";
};

// Adds the flags to `cmd`; `size_help` says what --size defaults to for that command.
void AddCameraFlags(CLI::App* cmd, CameraFlags& flags, const std::string& size_help);

// Fills the rate, format, focus and exposure of `options` (the size is the command's to choose).
void ApplyCameraFlags(const CameraFlags& flags, recordings::V4l2Options& options);

// The focus a session asks the camera for: --focus when given; else the calibration's own focus
// position where it has one (auto-focus off there: the focal length the calibration measured);
// else "lock" (auto-focus off where it stands).
std::string SessionFocus(const CameraFlags& flags, const calib::Camera& calibration);

// One line when the opened camera's focus is not the one `calibration` (named `whose`) holds
// for, or when its auto-focus still runs under a calibration with a focus; empty when they
// agree or either is not known.
std::string FocusMismatch(const recordings::V4l2Source& source, const calib::Camera& calibration,
                          const std::string& whose);

// "lock", "auto", "keep" or a whole number for --focus; "auto", "lock" or a whole number for
// --exposure: CLI11 validators whose message names the flag.
CLI::Validator FocusCheck();
CLI::Validator ExposureCheck();

}  // namespace arview::app
