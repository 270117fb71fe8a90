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

// The whole of a text file the recordings module reads (trajectories, camera files of imported
// data sets): only a regular file of sane size, since a FIFO or a link to /dev/zero would never
// end; RecordingError naming the file otherwise.
std::string ReadRecordingText(const std::filesystem::path& file);

// Reads a TUM file; '#' comments and blank lines are skipped. A malformed line throws
// RecordingError naming the file and the line number.
Trajectory ReadTum(const std::filesystem::path& path);
void WriteTum(const Trajectory& trajectory, const std::filesystem::path& path,
              const std::string& header_comment = "");

}  // namespace arview::recordings
