#pragma once
// Writing a recording frame by frame (arview record): each frame goes to frames/NNNNNN.png
// first and only then gets its line in frames.txt, written with one append and flushed, so an
// interrupted recording is always a valid one whose frames.txt lists only frames on disk.

#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>

#include <opencv2/core.hpp>

#include "base/cancellation.h"
#include "calib/camera.h"
#include "recordings/frame_source.h"

namespace arview::recordings {

class RecordingWriter {
 public:
  // Prepares the folder (PrepareRecordingFolder) and writes camera.yaml when a camera is given.
  // Without one the recording needs a camera.yaml (arview calibrate) before it can be loaded.
  RecordingWriter(const std::filesystem::path& root, const std::optional<calib::Camera>& camera, bool overwrite);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // Appends one BGR (or grey) frame. Throws RecordingError, writing nothing, when the timestamp
  // does not increase, the size differs from the camera's or from the first frame's, or a
  // write fails.
  void Append(const cv::Mat& image, double timestamp);
  // When no frame was appended: closes frames.txt and deletes what the constructor created
  // (frames.txt, camera.yaml, frames/, and the folder if it is then empty). Returns whether it
  // did; a recording with frames is never touched.
  bool RemoveIfEmpty();
  int frame_count() const { return count_; }
  double last_timestamp() const { return last_timestamp_; }
  const std::filesystem::path& root() const { return root_; }

 private:
  std::filesystem::path root_;
  std::optional<calib::Camera> camera_;
  int fd_ = -1;  // frames.txt, opened for appending
  int count_ = 0;
  double last_timestamp_ = 0;
  cv::Size size_;
};

struct RecordStats {
  int frames = 0;
  int skipped = 0;         // frames whose timestamp did not increase
  double seconds = 0;      // span of the recorded timestamps
  double fps = 0;          // frames / wall-clock time so far
};

// Copies frames from `source` into `writer` until the source ends, `cancel` is cancelled, or the
// frame timestamps span `max_seconds` (0 = no limit). Timestamps are stored relative to the
// first frame. `progress` (optional) is called after every frame written, with that frame (its
// timestamp relative to the first, as stored). A SourceError from the
// source propagates; the frames written before it stay a valid recording.
RecordStats RecordFrames(FrameSource& source, RecordingWriter& writer, double max_seconds,
                         const CancellationToken& cancel,
                         const std::function<void(const Frame&, const RecordStats&)>& progress = {});

}  // namespace arview::recordings
