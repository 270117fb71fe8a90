#include "recordings/recorder.h"

#include "base/image_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>

#include <opencv2/imgcodecs.hpp>

namespace arview::recordings {

namespace fs = std::filesystem;

namespace {

void WriteAll(int fd, const std::string& text, const fs::path& file) {
  // One write() of a short line with O_APPEND. On a full disk (or at the file-size limit) it can
  // write part of the line and return the count: the part is cut off again, so that frames.txt
  // never ends in half a line (LoadRecording would refuse the whole recording).
  const off_t before = ::lseek(fd, 0, SEEK_END);
  const ssize_t n = ::write(fd, text.data(), text.size());
  if (n == static_cast<ssize_t>(text.size())) return;
  const std::string why = n < 0 ? std::strerror(errno)
                                : "only " + std::to_string(n) + " of " + std::to_string(text.size()) +
                                      " bytes written: the disk is full or the file at its size limit";
  if (n > 0 && (before < 0 || ::ftruncate(fd, before) != 0)) {
    throw RecordingError(file.string() + ": cannot write (" + why + "), and cannot cut the partial line off again");
  }
  throw RecordingError(file.string() + ": cannot write (" + why + ")");
}

}  // namespace

RecordingWriter::RecordingWriter(const fs::path& root, const std::optional<calib::Camera>& camera, bool overwrite)
    : root_(root), camera_(camera) {
  PrepareRecordingFolder(root_, overwrite);
  try {
    if (camera_) {
      try {
        calib::SaveCamera(*camera_, root_ / "camera.yaml");
      } catch (const calib::CameraError& e) {
        throw RecordingError(e.what());
      }
      size_ = camera_->Size();
    }
    const fs::path file = root_ / "frames.txt";
    fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0) throw RecordingError(file.string() + ": cannot create (" + std::string(std::strerror(errno)) + ")");
    WriteAll(fd_, "# timestamp path\n", file);
  } catch (const RecordingError&) {
    // Issue 17: on a full disk the header did not fit and an empty frames.txt and frames/ were
    // left, a recording of nothing. Nothing was recorded: nothing stays.
    RemoveIfEmpty();
    throw;
  }
}

RecordingWriter::~RecordingWriter() {
  if (fd_ >= 0) ::close(fd_);
}

bool RecordingWriter::RemoveIfEmpty() {
  if (count_ > 0) return false;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  std::error_code ec;
  fs::remove(root_ / "frames.txt", ec);
  fs::remove(root_ / "camera.yaml", ec);
  fs::remove_all(root_ / "frames", ec);
  if (fs::is_empty(root_, ec)) fs::remove(root_, ec);
  return true;
}

void RecordingWriter::Append(const cv::Mat& image, double timestamp) {
  const fs::path list = root_ / "frames.txt";
  if (fd_ < 0) throw RecordingError(list.string() + ": the recording was removed");
  if (image.empty()) throw RecordingError(list.string() + ": cannot record an empty frame");
  if (!std::isfinite(timestamp) || (count_ > 0 && timestamp <= last_timestamp_)) {
    throw RecordingError(list.string() + ": frame timestamp " + std::to_string(timestamp) +
                         " does not follow " + std::to_string(last_timestamp_));
  }
  if (size_.area() > 0 && image.size() != size_) {
    throw RecordingError(list.string() + ": frame is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                         ", the recording is " + std::to_string(size_.width) + "x" + std::to_string(size_.height));
  }
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", count_);
  const std::string rel = std::string("frames/") + name;
  try {
    WriteImageAtomically(root_ / rel, image, {cv::IMWRITE_PNG_COMPRESSION, 1});  // speed over size
  } catch (const RecordingError&) {
    throw;
  } catch (const Error& e) {  // a full disk: the frame is not written, frames.txt untouched
    throw RecordingError(e.what());
  }
  char line[96];
  std::snprintf(line, sizeof(line), "%.9f %s\n", timestamp, rel.c_str());
  try {
    WriteAll(fd_, line, list);
  } catch (const RecordingError&) {
    std::error_code ec;
    fs::remove(root_ / rel, ec);  // not listed: it would be a stray file in frames/
    throw;
  }
  if (size_.area() == 0) size_ = image.size();
  last_timestamp_ = timestamp;
  ++count_;
}

RecordStats RecordFrames(FrameSource& source, RecordingWriter& writer, double max_seconds,
                         const CancellationToken& cancel,
                         const std::function<void(const Frame&, const RecordStats&)>& progress) {
  RecordStats stats;
  const auto wall_start = std::chrono::steady_clock::now();
  Frame frame;
  double t0 = 0;
  bool first = true;
  while (!cancel.IsCancelled() && source.Next(frame)) {
    if (first) {
      t0 = frame.timestamp;
      first = false;
    }
    const double t = frame.timestamp - t0;
    if (max_seconds > 0 && t >= max_seconds) break;
    if (writer.frame_count() > 0 && t <= writer.last_timestamp()) {
      ++stats.skipped;
      continue;
    }
    writer.Append(frame.image, t);
    stats.frames = writer.frame_count();
    stats.seconds = t;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    stats.fps = wall > 0 ? stats.frames / wall : 0;
    frame.timestamp = t;
    if (progress) progress(frame, stats);
  }
  return stats;
}

}  // namespace arview::recordings
