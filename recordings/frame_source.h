#pragma once
// Where frames come from: a recording being replayed or a live V4L2 camera. The tracker and
// the real-time pipeline read every source through this one interface.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "recordings/recording.h"

namespace arview::recordings {

struct Frame {
  cv::Mat image;          // BGR, 8 bits per channel
  double timestamp = 0;   // seconds (recording: frames.txt time; live: kernel capture time)
  int64_t index = 0;      // recording: the frame's 0-based line in frames.txt; live: sequence number
  // When the frame was captured, on the steady clock (CLOCK_MONOTONIC on Linux): a camera's
  // kernel timestamp; a paced replay's due time; an unpaced replay's delivery. Latency is
  // measured from here. The epoch (zero): unknown, the pipeline takes the frame's arrival.
  std::chrono::steady_clock::time_point capture_time{};
};

// What a source discarded before delivering, counted since it started. Read by the progress
// line while the capture thread runs: a source keeps them in atomics.
struct SourceCounts {
  int64_t driver_dropped = 0;   // a camera: frames the driver dropped (gaps in its sequence numbers)
  int64_t corrupt_skipped = 0;  // a camera: frames flagged in error or undecodable
  int64_t stale_skipped = 0;    // a camera: frames that waited in its buffers while a newer one was ready
};

// A source that fails while running (file unreadable, device gone); the message names it.
struct SourceError : RecordingError {
  using RecordingError::RecordingError;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame; false at the end of the stream (or after Stop()). Throws SourceError.
  virtual bool Next(Frame& frame) = 0;
  // The recording folder or device path, for messages.
  virtual std::string Name() const = 0;
  // Safe to call from another thread while Next runs.
  virtual SourceCounts Counts() const { return {}; }
};

struct ReplayOptions {
  // Deliver frames at the recorded rate (sleeping between them) instead of as fast as possible.
  bool paced = false;
  double speed = 1.0;  // with paced: 2 = twice the recorded rate
  // Start again after the last frame, forever. Timestamps keep increasing across passes (each
  // pass is shifted by the recording's duration plus one median frame interval).
  bool loop = false;
  // With loop: stop after this many passes over the frames (0: never). `arview replay --loop N`.
  long passes = 0;
  // 0-based indices into frames.txt to deliver, in this order (ParseFrameSpec); empty = all.
  std::vector<int> frames;
  // With paced: frames read and decoded up to this many ahead of their time, on a thread of the
  // source's own, from its construction on, as a camera's driver holds the frames its sensor has
  // made: a frame is then due with its pixels ready, and a moment when the decoding falls behind
  // (the session's busy start) is made up before the frame is due. 0: each frame is read
  // when the one before it has been taken.
  int read_ahead = 8;
};

// Replays a recording folder: one image per frame, or one video file decoded with OpenCV's
// FFmpeg backend (whose frame count must match frames.txt).
class RecordingSource : public FrameSource {
 public:
  explicit RecordingSource(Recording recording, ReplayOptions options = {});
  ~RecordingSource() override;
  RecordingSource(const RecordingSource&) = delete;
  RecordingSource& operator=(const RecordingSource&) = delete;
  bool Next(Frame& frame) override;
  std::string Name() const override { return recording_.root.string(); }
  const Recording& recording() const { return recording_; }

 private:
  struct Read {
    cv::Mat image;
    int index = 0;
    double timestamp = 0;
  };
  // The next frame of the order (across the loop's passes), read and decoded; none at the end.
  std::optional<Read> ReadNext();
  void ReadAhead();  // the read-ahead thread
  cv::Mat ReadFrame(int index);
  cv::Mat ReadVideoFrame(int index);
  // Sleeps until the frame at `timestamp` is due and returns when that is.
  std::chrono::steady_clock::time_point WaitUntilDue(double timestamp);

  Recording recording_;
  ReplayOptions options_;
  std::vector<int> order_;
  size_t cursor_ = 0;
  double loop_offset_ = 0;
  long pass_ = 1;  // the pass being delivered, from 1
  double pass_length_ = 0;
  cv::VideoCapture video_;
  int video_next_ = 0;  // index of the frame the next video read returns
  bool started_ = false;
  std::chrono::steady_clock::time_point wall_start_;
  double first_timestamp_ = 0;

  // Read-ahead (options_.paced with read_ahead > 0): the thread owns everything above but the
  // pacing; these are shared with Next, under ahead_mutex_.
  std::mutex ahead_mutex_;
  std::condition_variable ahead_changed_;
  std::deque<Read> ahead_;
  bool ahead_ended_ = false;        // the thread has read its last frame, or failed
  std::exception_ptr ahead_error_;  // why it failed, given to Next after the frames before it
  bool stopping_ = false;
  std::thread ahead_thread_;        // last: started when everything it uses is made
};

}  // namespace arview::recordings
