#include "recordings/frame_source.h"

#include "base/image_file.h"
#include "base/stats.h"

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
  if (cursor_ == order_.size()) {
    if (!options_.loop || (options_.passes > 0 && pass_ >= options_.passes)) return false;
    cursor_ = 0;
    ++pass_;
    loop_offset_ += pass_length_;
  }
  const int index = order_[cursor_++];
  frame.image = ReadFrame(index);
  frame.index = index;
  frame.timestamp = recording_.frames[index].timestamp + loop_offset_;
  // Paced, the frame is "captured" when it is due, as a camera's would be: a slow read shows as
  // latency. Unpaced, it is captured when it is read.
  frame.capture_time = options_.paced ? WaitUntilDue(frame.timestamp) : std::chrono::steady_clock::now();
  return true;
}

}  // namespace arview::recordings
