#pragma once
// TUM trajectory files: one line per pose, "timestamp tx ty tz qx qy qz qw", camera-to-world.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/atomic_file.h"
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

// A TUM file written pose by pose as a long session runs, so that its poses are on disk and not
// held in memory (a live session's would grow by 80 bytes a frame, 7.5 MiB an hour at 26 Hz:
// docs/reliability.md). Written under a partial name (base/atomic_file.h, PendingOutput), renamed
// into place by Finish(); removed when destroyed unfinished, so that an interrupted run never
// leaves a file that looks complete. The same text as WriteTum for the same poses.
class TumFileWriter {
 public:
  // Throws arview::Error naming `path` when it cannot be written or is a folder.
  TumFileWriter(const std::filesystem::path& path, const std::string& header_comment = "");

  // One pose's line, flushed to the kernel. From one thread at a time.
  void Add(const StampedPose& pose);
  // On disk (fsync), then renamed into place. Throws arview::Error naming the file.
  void Finish() { file_.Finish(); }
  std::size_t poses() const { return poses_; }

 private:
  StreamedFile file_;
  std::size_t poses_ = 0;
};

}  // namespace arview::recordings
