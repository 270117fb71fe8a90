#pragma once
// Live frames from a V4L2 camera (linux/videodev2.h): capability query, size and format
// negotiation (YUYV or MJPEG), memory-mapped streaming buffers, poll with a timeout, decode to
// BGR, kernel timestamps. Every failure is one SourceError naming the device.

#include <poll.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/cancellation.h"

#include "recordings/frame_source.h"

namespace arview::recordings {

// The system calls V4l2Source makes. The default passes them to the kernel; tests stand in a
// simulated camera (formats, streaming, stalls, unplugging) since no camera is attached here.
// Each returns what the system call returns and sets errno the same way.
class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int Stat(const char* path, struct stat* st) = 0;
  virtual int Open(const char* path, int flags) = 0;
  virtual int Close(int fd) = 0;
  virtual int Ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual int Poll(pollfd* fds, nfds_t count, int timeout_ms) = 0;
  virtual void* Mmap(size_t length, int fd, off_t offset) = 0;  // MAP_FAILED on failure
  virtual int Munmap(void* address, size_t length) = 0;
};
V4l2Io& SystemV4l2Io();

inline constexpr double kFirstFrameTimeout = 5.0;  // seconds

struct V4l2Options {
  int width = 640;   // requested; the driver may pick the nearest size it supports (see size())
  int height = 480;
  // "auto" (YUYV if offered, else MJPEG), "yuyv" or "mjpeg".
  std::string format = "auto";
  int buffer_count = 4;
  // No frame within this time is an error (a stalled or unplugged camera). The first frame
  // may take up to kFirstFrameTimeout (cameras settle their exposure first).
  double timeout_seconds = 1.0;
  // Once cancelled (Ctrl-C, SIGTERM), Next() returns false within ~0.1 s.
  CancellationToken cancel;
};

class V4l2Source : public FrameSource {
 public:
  // Opens the device and starts streaming; throws SourceError (no such device, permission,
  // not a capture device, busy, no supported format, ...).
  V4l2Source(const std::string& device, V4l2Options options = {}, V4l2Io& io = SystemV4l2Io());
  ~V4l2Source() override;
  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;

  // Next frame with the kernel's capture timestamp (seconds, the driver's clock, normally
  // CLOCK_MONOTONIC; the dequeue time on CLOCK_MONOTONIC for drivers that give none) and the
  // driver's sequence number as index. Frames the driver flags as
  // corrupt are skipped. Throws SourceError when the device disappears or stalls.
  bool Next(Frame& frame) override;
  std::string Name() const override { return device_; }

  cv::Size size() const { return {width_, height_}; }
  std::string FormatName() const;  // "YUYV" or "MJPEG"
  std::string CardName() const { return card_; }
  int64_t skipped_frames() const { return skipped_; }

 private:
  struct Buffer {
    void* start = nullptr;
    size_t length = 0;
  };
  [[noreturn]] void Fail(const std::string& problem) const;
  void QueryCapabilities();
  void NegotiateFormat();
  void StartStreaming();
  void Shutdown();

  int Ioctl(unsigned long request, void* arg);  // retried on EINTR

  std::string device_;
  V4l2Options options_;
  V4l2Io& io_;
  int fd_ = -1;
  std::string card_;
  uint32_t pixel_format_ = 0;
  int width_ = 0, height_ = 0;
  int stride_ = 0;
  std::vector<Buffer> buffers_;
  bool streaming_ = false;
  int64_t skipped_ = 0;
  int64_t delivered_ = 0;
};

// Packed YUYV 4:2:2 (two bytes per pixel, `stride` bytes per row) to BGR. Throws SourceError
// when the buffer is too short for the size, or the width is odd.
cv::Mat DecodeYuyv(const uint8_t* data, size_t bytes, int width, int height, int stride);

// One MJPEG frame to BGR. Many UVC cameras omit the Huffman tables (the JPEG standard's
// Annex K tables are implied); libjpeg-turbo, behind OpenCV on Debian, supplies them itself
// (the tests check it). Throws SourceError when the data is not a decodable JPEG or has another
// size than expected (0 = don't check).
cv::Mat DecodeMjpeg(const uint8_t* data, size_t bytes, int expected_width = 0, int expected_height = 0);

}  // namespace arview::recordings
