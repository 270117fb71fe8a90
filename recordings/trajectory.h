#pragma once
// TUM trajectory files: one line per pose, "timestamp tx ty tz qx qy qz qw", camera-to-world.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"
#include "calib/pose.h"

namespace arview::recordings {

struct RecordingError : Error {
  using Error::Error;
};

struct StampedPose {
  double timestamp = 0;
  calib::Pose pose;  // world → camera
};

using Trajectory = std::vector<StampedPose>;

// Reads a TUM file; '#' comments and blank lines are skipped. A malformed line throws
// RecordingError naming the file and the line number.
Trajectory ReadTum(const std::filesystem::path& path);
void WriteTum(const Trajectory& trajectory, const std::filesystem::path& path,
              const std::string& header_comment = "");

}  // namespace arview::recordings
