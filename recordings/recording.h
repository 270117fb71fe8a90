#pragma once
// The recording folder (docs/architecture.md, "The recording folder"):
//   camera.yaml, frames/ (images, or one video file), frames.txt ("timestamp relative/path"),
//   groundtruth.txt (optional, TUM, camera-to-world).
// For a video, every line of frames.txt names the same video file and frames are read in order.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/camera.h"
#include "recordings/trajectory.h"

namespace arview::recordings {

struct FrameEntry {
  double timestamp = 0;
  std::string path;  // relative to the recording folder
};

struct Recording {
  std::filesystem::path root;
  calib::Camera camera;
  std::vector<FrameEntry> frames;
  std::optional<Trajectory> groundtruth;

  // True when frames.txt names one video file rather than one image per frame.
  bool IsVideo() const;
  std::filesystem::path FramePath(size_t index) const { return root / frames.at(index).path; }
  // Reads one still frame (image recordings only); throws RecordingError naming the file.
  cv::Mat ReadImage(size_t index) const;
};

// Loads and validates a recording folder: camera.yaml, frames.txt (timestamps strictly
// increasing, every file present), groundtruth.txt when present.
Recording LoadRecording(const std::filesystem::path& root);

// Reads a "timestamp path" list (frames.txt, TUM's rgb.txt): '#' comments and blank lines
// skipped, timestamps strictly increasing; throws RecordingError naming file and line.
std::vector<FrameEntry> ReadFrameList(const std::filesystem::path& file);

// Makes `root` an empty recording folder with an empty frames/ inside. A folder that already
// holds a recording (has frames.txt) is cleared only with overwrite (frames.txt goes first, so
// that a failure never leaves a valid-looking half); any other non-empty folder is refused, so
// that a typo never deletes data. Throws RecordingError.
void PrepareRecordingFolder(const std::filesystem::path& root, bool overwrite);

// Writes frames.txt atomically (a temporary file renamed into place).
void WriteFramesTxt(const std::filesystem::path& root, const std::vector<FrameEntry>& frames);

// "--frames" syntax: 0-based indices, comma-separated items, each "i" or "a-b" or "a-b:step",
// inclusive. Returns sorted unique indices; throws RecordingError on bad syntax or an index
// outside [0, frame_count).
std::vector<int> ParseFrameSpec(const std::string& spec, int frame_count);

}  // namespace arview::recordings
