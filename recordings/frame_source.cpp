#include "recordings/frame_source.h"

#include "base/image_file.h"
#include "base/stats.h"

#include <pthread.h>

#include <algorithm>
#include <numeric>
#include <thread>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace arview::recordings {

RecordingSource::RecordingSource(Recording recording, ReplayOptions options)
    : recording_(std::move(recording)), options_(std::move(options)) {
  const int n = static_cast<int>(recording_.frames.size());
  if (n == 0) throw SourceError(recording_.root.string() + ": the recording lists no frames");
  if (!(options_.speed > 0) || !std::isfinite(options_.speed)) {
    throw SourceError(recording_.root.string() + ": replay speed must be a positive number");
  }
  order_ = options_.frames;
  if (order_.empty()) {
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), 0);
  }
  for (int i : order_) {
    if (i < 0 || i >= n) {
      throw SourceError(recording_.root.string() + ": frame " + std::to_string(i) + " is beyond the recording's " +
                        std::to_string(n) + " frames");
    }
  }
  // One pass lasts from the first to the last frame plus a typical frame interval, so that
  // looped timestamps keep a steady rate across the seam.
  std::vector<double> gaps;
  for (size_t k = 1; k < order_.size(); ++k) {
    gaps.push_back(std::abs(recording_.frames[order_[k]].timestamp - recording_.frames[order_[k - 1]].timestamp));
  }
  const double median_gap = gaps.empty() ? 1.0 : Median(gaps);
  pass_length_ = recording_.frames[order_.back()].timestamp - recording_.frames[order_.front()].timestamp + median_gap;
  if (recording_.IsVideo()) {
    const std::string file = recording_.FramePath(0).string();
    if (!video_.open(file, cv::CAP_FFMPEG)) {
      throw SourceError(file + ": cannot be opened as a video (OpenCV FFmpeg backend)");
    }
  }
  if (options_.paced && options_.read_ahead > 0) ahead_thread_ = std::thread(&RecordingSource::ReadAhead, this);
}

RecordingSource::~RecordingSource() {
  if (!ahead_thread_.joinable()) return;
  {
    const std::lock_guard lock(ahead_mutex_);
    stopping_ = true;
  }
  ahead_changed_.notify_all();
  ahead_thread_.join();
}

void RecordingSource::ReadAhead() {
  pthread_setname_np(pthread_self(), "arview-readahd");  // shown by top -H
  for (;;) {
    {
      std::unique_lock lock(ahead_mutex_);
      ahead_changed_.wait(lock, [&] { return stopping_ || static_cast<int>(ahead_.size()) < options_.read_ahead; });
      if (stopping_) return;
    }
    std::optional<Read> read;
    std::exception_ptr error;
    try {
      read = ReadNext();
    } catch (...) {
      error = std::current_exception();
    }
    {
      const std::lock_guard lock(ahead_mutex_);
      if (read) ahead_.push_back(std::move(*read));
      else ahead_ended_ = true;
      ahead_error_ = error;
    }
    ahead_changed_.notify_all();
    if (!read) return;
  }
}

std::optional<RecordingSource::Read> RecordingSource::ReadNext() {
  if (cursor_ == order_.size()) {
    if (!options_.loop || (options_.passes > 0 && pass_ >= options_.passes)) return std::nullopt;
    cursor_ = 0;
    ++pass_;
    loop_offset_ += pass_length_;
  }
  const int index = order_[cursor_++];
  return Read{ReadFrame(index), index, recording_.frames[index].timestamp + loop_offset_};
}

cv::Mat RecordingSource::ReadVideoFrame(int index) {
  const std::string file = recording_.FramePath(0).string();
  if (index < video_next_) {  // a jump backwards (a loop, or a --frames order): start over
    video_.release();
    if (!video_.open(file, cv::CAP_FFMPEG)) throw SourceError(file + ": cannot be reopened as a video");
    video_next_ = 0;
  }
  cv::Mat image;
  while (video_next_ <= index) {
    const bool ok = video_next_ < index ? video_.grab() : video_.read(image);
    if (!ok) {
      throw SourceError(file + ": the video ends after " + std::to_string(video_next_) + " frames but frames.txt lists " +
                        std::to_string(recording_.frames.size()));
    }
    ++video_next_;
  }
  return image;
}

cv::Mat RecordingSource::ReadFrame(int index) {
  cv::Mat image;
  if (recording_.IsVideo()) {
    image = ReadVideoFrame(index);
  } else {
    const std::string file = recording_.FramePath(index).string();
    try {
      image = ReadImageFile(file, cv::IMREAD_COLOR);
    } catch (const Error& e) {
      throw SourceError(e.what());
    }
  }
  if (image.size() != recording_.camera.Size()) {
    throw SourceError(recording_.FramePath(index).string() + ": frame " + std::to_string(index) + " is " +
                      std::to_string(image.cols) + "x" + std::to_string(image.rows) + " but camera.yaml says " +
                      std::to_string(recording_.camera.width) + "x" + std::to_string(recording_.camera.height));
  }
  return image;
}

std::chrono::steady_clock::time_point RecordingSource::WaitUntilDue(double timestamp) {
  if (!started_) {
    started_ = true;
    wall_start_ = std::chrono::steady_clock::now();
    first_timestamp_ = timestamp;
    return wall_start_;
  }
  const auto due = wall_start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>((timestamp - first_timestamp_) / options_.speed));
  std::this_thread::sleep_until(due);
  return due;
}

bool RecordingSource::Next(Frame& frame) {
  std::optional<Read> read;
  if (ahead_thread_.joinable()) {
    std::unique_lock lock(ahead_mutex_);
    ahead_changed_.wait(lock, [&] { return !ahead_.empty() || ahead_ended_; });
    if (ahead_.empty()) {
      if (ahead_error_) std::rethrow_exception(ahead_error_);
      return false;
    }
    read = std::move(ahead_.front());
    ahead_.pop_front();
    lock.unlock();
    ahead_changed_.notify_all();
  } else {
    read = ReadNext();
    if (!read) return false;
  }
  frame.image = std::move(read->image);
  frame.index = read->index;
  frame.timestamp = read->timestamp;
  // Paced, the frame is "captured" when it is due, as a camera's would be: a slow read shows as
  // latency. Unpaced, it is captured when it is read.
  frame.capture_time = options_.paced ? WaitUntilDue(frame.timestamp) : std::chrono::steady_clock::now();
  return true;
}

}  // namespace arview::recordings
