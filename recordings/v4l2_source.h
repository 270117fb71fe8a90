#pragma once
// Live frames from a V4L2 camera (linux/videodev2.h): what the camera offers (formats, frame
// sizes, frame rates, controls), the set-up of a session (size, format, rate, focus, exposure),
// memory-mapped streaming buffers started at the first frame asked for, poll with a timeout,
// the freshest frame only, decode to BGR, kernel timestamps. Every failure is one SourceError
// naming the device.

#include <poll.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/cancellation.h"

#include "recordings/frame_source.h"

struct v4l2_buffer;  // linux/videodev2.h, kept out of this header

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

// ---- What a camera offers (VIDIOC_ENUM_FMT, ENUM_FRAMESIZES, ENUM_FRAMEINTERVALS) ----

struct FrameSizeRates {
  int width = 0, height = 0;
  std::vector<double> fps;        // the rates offered at this size, highest first; empty: not enumerable
  bool continuous_rates = false;  // a stepwise interval range: any rate from fps.back() to fps.front()
  double MaxFps() const { return fps.empty() ? 0.0 : fps.front(); }
};

struct FormatCapabilities {
  uint32_t fourcc = 0;
  std::string name;         // the fourcc as text: "YUYV", "MJPG"
  std::string description;  // the driver's words
  // Discrete sizes as listed. A stepwise range is listed at its ends and at the common sizes
  // within it (640x480, 1280x720, 1920x1080), with stepwise_sizes set and the range kept.
  std::vector<FrameSizeRates> sizes;
  bool stepwise_sizes = false;
  cv::Size min_size, max_size;
};

struct CameraCapabilities {
  std::vector<FormatCapabilities> formats;  // in the driver's order; empty sizes: not enumerable

  const FormatCapabilities* Find(uint32_t fourcc) const;
  // The listed size of `fourcc` nearest to `wanted` (exact when listed, else the smallest
  // difference in width plus height, as drivers choose); {} when no sizes are listed.
  cv::Size NearestSize(uint32_t fourcc, cv::Size wanted) const;
  // The highest rate `fourcc` offers at exactly `size`; 0 when not listed.
  double MaxFps(uint32_t fourcc, cv::Size size) const;
  const FrameSizeRates* Rates(uint32_t fourcc, cv::Size size) const;
};

// ---- Controls (VIDIOC_QUERYCTRL with V4L2_CTRL_FLAG_NEXT_CTRL, QUERYMENU, G_CTRL) ----

struct ControlMenuItem {
  int64_t value = 0;
  std::string name;
};

struct CameraControl {
  uint32_t id = 0;
  std::string name;  // the driver's: "Focus, Automatic Continuous", "Exposure Time, Absolute"
  uint32_t type = 0;  // V4L2_CTRL_TYPE_*
  int64_t minimum = 0, maximum = 0, step = 1, default_value = 0;
  uint32_t flags = 0;  // V4L2_CTRL_FLAG_*
  bool value_known = false;  // G_CTRL answered (not for write-only or button controls)
  int64_t value = 0;
  std::vector<ControlMenuItem> menu;  // the menu entries the driver names, for menu controls

  bool Inactive() const;  // e.g. the focus position while auto-focus runs
  std::string TypeName() const;  // "int", "bool", "menu", "button", ...
};

// One device as `arview camera info` shows it. Opening for this does not stream.
struct CameraInfo {
  std::string device, card, driver, bus;
  CameraCapabilities capabilities;
  std::vector<CameraControl> controls;
  cv::Size current_size;       // G_FMT
  std::string current_format;  // fourcc text
  double current_fps = 0;      // G_PARM; 0: the driver does not say
};
// Throws SourceError (no such device, permission, not a capture device, ...).
CameraInfo DescribeCamera(const std::string& device, V4l2Io& io = SystemV4l2Io());

// One /dev/video* node as `arview camera list` shows it.
struct CameraListing {
  std::string device, card, driver, bus;
  bool capture = false;  // a capture node (a webcam also has metadata nodes, which are not)
  std::string problem;   // why it could not be asked (busy, permission); empty when it answered
};
// The video nodes under `dev` (video0, video1, ... in number order).
std::vector<CameraListing> ListCameras(const std::filesystem::path& dev = "/dev", V4l2Io& io = SystemV4l2Io());

// ---- The live source ----

struct V4l2Options {
  int width = 640;   // requested; the driver may pick the nearest size it supports (see size())
  int height = 480;
  // "auto", "yuyv" or "mjpeg". auto takes YUYV (no compression artefacts, no decoding cost)
  // only where YUYV reaches the wanted rate at this size, else MJPEG: USB 2 carries YUYV at
  // 30 fps only up to about 640x480 (10 fps at 1280x720, 5 at 1920x1080).
  std::string format = "auto";
  // Frames per second to ask for (VIDIOC_S_PARM); 0: the highest the camera offers at the size.
  double fps = 0;
  // "keep" (leave the camera as it is), "auto" (auto-focus on), "lock" (auto-focus off where it
  // is: the default, since auto-focus moves the lens and so changes the focal length under a
  // fixed calibration) or a number (auto-focus off, V4L2_CID_FOCUS_ABSOLUTE set, in the
  // control's units).
  std::string focus = "lock";
  // "auto" (the camera's automatic exposure: the default), "lock" (manual at the current
  // exposure time, so that dim light cannot lengthen it and halve the frame rate) or a number
  // (V4L2_CID_EXPOSURE_ABSOLUTE in the control's units, 100 µs on UVC cameras).
  std::string exposure = "auto";
  int buffer_count = 4;
  // Live use: each Next() returns the newest frame ready and puts the older ones back unread
  // (a frame shown late is worse than one not shown). false: every frame in order, as long as
  // the buffers hold them (a recording).
  bool newest_only = true;
  // No frame within this time is an error (a stalled or unplugged camera). The first frame
  // may take up to kFirstFrameTimeout (cameras settle their exposure first).
  double timeout_seconds = 1.0;
  // Once cancelled (Ctrl-C, SIGTERM), Next() returns false within ~0.1 s.
  CancellationToken cancel;
};

class V4l2Source : public FrameSource {
 public:
  // Opens the device, reads what it offers, negotiates format, size and rate, applies focus and
  // exposure and maps the buffers; throws SourceError (no such device, permission, not a
  // capture device, busy, no supported format, a control value out of range, ...). Streaming
  // starts at the first Next(), so that no frame waits in the driver's buffers while the
  // caller prepares (the tracker's warm-up): the first frame delivered is a fresh one.
  V4l2Source(const std::string& device, V4l2Options options = {}, V4l2Io& io = SystemV4l2Io());
  ~V4l2Source() override;
  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;

  // The newest frame ready: every buffer the driver has filled is dequeued and only the newest
  // decoded; the older ones go back undecoded (counted stale_skipped). (With newest_only false:
  // the oldest ready frame.) The frame carries the
  // kernel's capture timestamp (seconds, the driver's clock, normally CLOCK_MONOTONIC; the
  // dequeue time for drivers that give none) as `timestamp` and `capture_time`, and the driver's
  // sequence number as index. Frames the driver flags or that do not decode are skipped
  // (corrupt_skipped); gaps in the sequence numbers are counted (driver_dropped). Throws
  // SourceError when the device disappears or stalls.
  bool Next(Frame& frame) override;
  std::string Name() const override { return device_; }
  SourceCounts Counts() const override;  // thread-safe

  // What was granted.
  cv::Size size() const { return {width_, height_}; }
  std::string FormatName() const;  // "YUYV" or "MJPEG"
  double fps() const { return granted_fps_; }  // 0: the driver does not say
  double requested_fps() const { return options_.fps; }
  std::string CardName() const { return card_; }
  // "/dev/video0: <card>, 1280x720 MJPEG at 30 fps (asked 30)": the one line a command prints.
  std::string GrantedLine() const;
  // What the set-up could not do and the user should know, one line each (a camera without a
  // focus control, a rate lower than asked); not errors.
  const std::vector<std::string>& notes() const { return notes_; }
  const CameraCapabilities& capabilities() const { return capabilities_; }
  const std::vector<CameraControl>& controls() const { return controls_; }
  bool streaming() const { return streaming_; }
  int64_t skipped_frames() const { return corrupt_skipped_.load(); }  // = Counts().corrupt_skipped
  // The lens focus position after the set-up (V4L2_CID_FOCUS_ABSOLUTE, read back), and whether
  // auto-focus is off; unset where the camera has no readable focus position.
  std::optional<int64_t> focus_position() const { return focus_position_; }
  bool focus_held() const { return focus_held_; }

 private:
  struct Buffer {
    void* start = nullptr;
    size_t length = 0;
  };
  [[noreturn]] void Fail(const std::string& problem) const;
  void ValidateOptions() const;
  void QueryCapabilities();
  uint32_t ChooseFormat() const;
  void NegotiateFormat();
  void NegotiateFrameRate();
  void ApplyFocus();
  void ReadBackFocus();
  void ApplyExposure();
  const CameraControl* FindControl(uint32_t id) const;
  bool TryReadControl(const CameraControl& control, int64_t& value);  // false: errno says why
  int64_t ReadControl(const CameraControl& control);  // throws SourceError
  bool TryWriteControl(const CameraControl& control, int64_t value);  // false: errno says why
  void CheckRange(const CameraControl& control, int64_t value, const std::string& what) const;
  void WriteControl(const CameraControl& control, int64_t value, const std::string& what);
  void MapBuffers();
  void StartStreaming();
  void Shutdown();
  // Dequeues every filled buffer (one with newest_only false); keeps the newest good one
  // (returns false when none), requeues the rest.
  bool TakeNewest(::v4l2_buffer& newest);
  void CountSequence(uint32_t sequence);
  void Requeue(::v4l2_buffer& buffer);
  cv::Mat Decode(const ::v4l2_buffer& buffer) const;

  int Ioctl(unsigned long request, void* arg);  // retried on EINTR

  std::string device_;
  V4l2Options options_;
  V4l2Io& io_;
  int fd_ = -1;
  std::string card_;
  CameraCapabilities capabilities_;
  std::vector<CameraControl> controls_;
  std::vector<std::string> notes_;
  std::optional<int64_t> focus_position_;
  bool focus_held_ = false;
  uint32_t pixel_format_ = 0;
  int width_ = 0, height_ = 0;
  int stride_ = 0;
  double granted_fps_ = 0;
  std::vector<Buffer> buffers_;
  bool streaming_ = false;
  bool sequence_seen_ = false;
  uint32_t last_sequence_ = 0;
  int64_t delivered_ = 0;
  std::atomic<int64_t> driver_dropped_{0}, corrupt_skipped_{0}, stale_skipped_{0};
};

// Packed YUYV 4:2:2 (two bytes per pixel, `stride` bytes per row) to BGR. Throws SourceError
// when the buffer is too short for the size, or the width is odd.
cv::Mat DecodeYuyv(const uint8_t* data, size_t bytes, int width, int height, int stride);

// One MJPEG frame to BGR. Many UVC cameras omit the Huffman tables (the JPEG standard's
// Annex K tables are implied); libjpeg-turbo, behind OpenCV on Debian, supplies them itself
// (the tests check it). Throws SourceError when the data is not a decodable JPEG or has another
// size than expected (0 = don't check).
cv::Mat DecodeMjpeg(const uint8_t* data, size_t bytes, int expected_width = 0, int expected_height = 0);

// The fourcc as four characters ("YUYV", "MJPG"); unprintable bytes as '?'.
std::string FourccText(uint32_t fourcc);

}  // namespace arview::recordings
