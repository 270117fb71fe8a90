#include "recordings/v4l2_source.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/jpeg_decoder.h"

#include "recordings/v4l2_detail.h"

namespace arview::recordings {

// ---- V4l2Source: set-up ----

int V4l2Source::Ioctl(unsigned long request, void* arg) { return RetryIoctl(io_, fd_, request, arg); }

void V4l2Source::Fail(const std::string& problem) const { DeviceFail(device_, problem); }

V4l2Source::V4l2Source(const std::string& device, V4l2Options options, V4l2Io& io)
    : device_(device), options_(std::move(options)), io_(io) {
  ValidateOptions();
  fd_ = OpenDevice(io_, device_);
  try {
    QueryCapabilities();
    NegotiateFormat();
    NegotiateFrameRate();
    ApplyFocus();
    ReadBackFocus();
    ApplyExposure();
    MapBuffers();
  } catch (...) {
    Shutdown();
    throw;
  }
}

V4l2Source::~V4l2Source() { Shutdown(); }

void V4l2Source::ValidateOptions() const {
  const V4l2Options& o = options_;
  if (o.width <= 0 || o.height <= 0) Fail("requested frame size must be positive");
  if (o.buffer_count < 2 || o.buffer_count > 32) Fail("buffer count must be between 2 and 32");
  if (!(o.timeout_seconds > 0)) Fail("frame timeout must be positive");
  if (!(o.fps >= 0 && o.fps <= 1000)) Fail("requested frame rate must be between 0 (the highest offered) and 1000");
  if (o.format != "auto" && o.format != "yuyv" && o.format != "mjpeg") {
    Fail("pixel format '" + o.format + "' is not auto, yuyv or mjpeg");
  }
  int64_t number = 0;
  if (o.focus != "keep" && o.focus != "auto" && o.focus != "lock" && !ParseInteger(o.focus, number)) {
    Fail("focus '" + o.focus + "' is not keep, auto, lock or a whole number");
  }
  if (o.exposure != "auto" && o.exposure != "lock" && !ParseInteger(o.exposure, number)) {
    Fail("exposure '" + o.exposure + "' is not auto, lock or a whole number");
  }
}

void V4l2Source::QueryCapabilities() {
  const DeviceIdentity id = QueryIdentity(io_, fd_, device_);
  card_ = id.card;
  CheckCaptureNode(id, device_);
  if (!(id.caps & V4L2_CAP_STREAMING)) Fail("does not support streaming I/O ('" + card_ + "')");
  capabilities_ = EnumerateCapabilities(io_, fd_);
  controls_ = EnumerateControls(io_, fd_);
}

uint32_t V4l2Source::ChooseFormat() const {
  const bool yuyv = capabilities_.Find(V4L2_PIX_FMT_YUYV) != nullptr;
  const uint32_t mjpeg = MjpegOffered(capabilities_);
  if (options_.format == "yuyv") return yuyv ? V4L2_PIX_FMT_YUYV : 0;
  if (options_.format == "mjpeg") return mjpeg;
  if (!yuyv || !mjpeg) return yuyv ? V4L2_PIX_FMT_YUYV : mjpeg;
  // Both offered: YUYV only where it reaches the rate wanted at the size the driver would give.
  const cv::Size wanted(options_.width, options_.height);
  const double yuyv_fps = capabilities_.MaxFps(V4L2_PIX_FMT_YUYV, capabilities_.NearestSize(V4L2_PIX_FMT_YUYV, wanted));
  const double mjpeg_fps = capabilities_.MaxFps(mjpeg, capabilities_.NearestSize(mjpeg, wanted));
  if (yuyv_fps <= 0) return V4L2_PIX_FMT_YUYV;  // rates not enumerable: nothing to judge by
  const double target = options_.fps > 0 ? options_.fps : mjpeg_fps;
  // 1% slack: 29.97 fps is the 30 fps asked for.
  return yuyv_fps >= 0.99 * target ? V4L2_PIX_FMT_YUYV : mjpeg;
}

void V4l2Source::NegotiateFormat() {
  const uint32_t chosen = ChooseFormat();
  if (chosen == 0) {
    std::string list;
    for (const FormatCapabilities& f : capabilities_.formats) list += (list.empty() ? "" : ", ") + f.name;
    Fail("no supported pixel format (the device offers " + (list.empty() ? std::string("none") : list) +
         "; arview reads " + (options_.format == "auto" ? "YUYV or MJPEG" : options_.format) + ")");
  }
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = static_cast<uint32_t>(options_.width);
  fmt.fmt.pix.height = static_cast<uint32_t>(options_.height);
  fmt.fmt.pix.pixelformat = chosen;
  fmt.fmt.pix.field = V4L2_FIELD_ANY;
  if (Ioctl(VIDIOC_S_FMT, &fmt) != 0) {
    if (errno == EBUSY) Fail("busy (another program is streaming from it)");
    Fail("cannot set format " + FourccText(chosen) + " " + SizeText(options_.width, options_.height) + " (" +
         ErrnoText(errno) + ")");
  }
  if (fmt.fmt.pix.pixelformat != chosen) {
    Fail("the driver replaced format " + FourccText(chosen) + " with " + FourccText(fmt.fmt.pix.pixelformat));
  }
  pixel_format_ = chosen;
  width_ = static_cast<int>(fmt.fmt.pix.width);
  height_ = static_cast<int>(fmt.fmt.pix.height);
  if (width_ <= 0 || height_ <= 0 || width_ > 16384 || height_ > 16384) {
    Fail("the driver granted an impossible frame size " + SizeText(width_, height_));
  }
  stride_ = static_cast<int>(fmt.fmt.pix.bytesperline);
  if (pixel_format_ == V4L2_PIX_FMT_YUYV && stride_ < 2 * width_) stride_ = 2 * width_;
}

void V4l2Source::NegotiateFrameRate() {
  const FrameSizeRates* rates = capabilities_.Rates(pixel_format_, size());
  const double offered = rates ? rates->MaxFps() : 0.0;
  const double wanted = options_.fps > 0 ? options_.fps : offered;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(VIDIOC_G_PARM, &parm) != 0) {
    if (options_.fps > 0) notes_.push_back(device_ + " does not let the frame rate be set or read; it runs at its own");
    return;
  }
  if (wanted > 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
    // The interval as a fraction: whole rates exactly (1/30), others to a thousandth (1000/7500).
    const bool whole = std::abs(wanted - std::round(wanted)) < 1e-9;
    parm.parm.capture.timeperframe.numerator = whole ? 1 : 1000;
    parm.parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(whole ? wanted : wanted * 1000));
    if (Ioctl(VIDIOC_S_PARM, &parm) != 0) {
      Fail("cannot set the frame rate to " + FpsText(wanted) + " fps (" + ErrnoText(errno) + ")");
    }
    v4l2_streamparm granted{};
    granted.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (Ioctl(VIDIOC_G_PARM, &granted) == 0) parm = granted;
  } else if (options_.fps > 0) {
    notes_.push_back(device_ + " does not let the frame rate be set; it runs at its own");
  }
  granted_fps_ = IntervalFps(parm.parm.capture.timeperframe);
  if (options_.fps > 0 && granted_fps_ > 0 && granted_fps_ < 0.99 * options_.fps) {
    std::string why = FormatName() + " at " + SizeText(width_, height_) + " offers at most " + FpsText(offered) + " fps";
    if (pixel_format_ == V4L2_PIX_FMT_YUYV && MjpegOffered(capabilities_)) why += " (MJPEG may be faster: --format mjpeg)";
    notes_.push_back(device_ + ": asked " + FpsText(options_.fps) + " fps, granted " + FpsText(granted_fps_) +
                     (offered > 0 ? "; " + why : ""));
  }
}

const CameraControl* V4l2Source::FindControl(uint32_t id) const {
  for (const CameraControl& c : controls_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

bool V4l2Source::TryReadControl(const CameraControl& control, int64_t& value) {
  v4l2_control c{};
  c.id = control.id;
  if (Ioctl(VIDIOC_G_CTRL, &c) != 0) return false;
  value = c.value;
  return true;
}

int64_t V4l2Source::ReadControl(const CameraControl& control) {
  int64_t value = 0;
  if (!TryReadControl(control, value)) Fail("cannot read control '" + control.name + "' (" + ErrnoText(errno) + ")");
  return value;
}

bool V4l2Source::TryWriteControl(const CameraControl& control, int64_t value) {
  v4l2_control c{};
  c.id = control.id;
  c.value = static_cast<int32_t>(value);
  return Ioctl(VIDIOC_S_CTRL, &c) == 0;
}

void V4l2Source::CheckRange(const CameraControl& control, int64_t value, const std::string& what) const {
  const std::string range = " (" + std::to_string(control.minimum) + ".." + std::to_string(control.maximum) +
                            ", step " + std::to_string(control.step) + ")";
  if (value < control.minimum || value > control.maximum)
    Fail(what + " " + std::to_string(value) + " is outside the range of control '" + control.name + "'" + range);
  // The driver would round a value between steps to one of them without a word (a focus of 7 held
  // at 5 or 10: another focal length than the one asked for).
  if (control.step > 1 && (value - control.minimum) % control.step != 0) {
    const int64_t below = value - (value - control.minimum) % control.step;
    std::string nearest = std::to_string(below);
    if (below + control.step <= control.maximum) nearest += " or " + std::to_string(below + control.step);
    Fail(what + " " + std::to_string(value) + " is between the steps of control '" + control.name + "'" + range +
         ": the camera holds " + nearest);
  }
}

void V4l2Source::WriteControl(const CameraControl& control, int64_t value, const std::string& what) {
  CheckRange(control, value, what);
  if (!TryWriteControl(control, value)) {
    Fail("cannot set control '" + control.name + "' to " + std::to_string(value) + " (" + ErrnoText(errno) + ")");
  }
}

void V4l2Source::ApplyFocus() {
  const std::string& focus = options_.focus;
  if (focus == "keep") return;
  const CameraControl* automatic = FindControl(V4L2_CID_FOCUS_AUTO);
  const CameraControl* absolute = FindControl(V4L2_CID_FOCUS_ABSOLUTE);
  if (focus == "auto" || focus == "lock") {
    if (automatic == nullptr) {
      notes_.push_back(device_ + " has no auto-focus control (a fixed-focus camera keeps its calibration); --focus " +
                       focus + " does nothing");
      return;
    }
    if (focus == "auto") return WriteControl(*automatic, 1, "focus auto");
    // Off where it stands. Some cameras move the lens to their stored position when auto-focus
    // is switched off: the position read before is written back. lock is the default: a camera
    // that refuses is worth a note, not the end of the session.
    const bool readable = absolute != nullptr && !(absolute->flags & V4L2_CTRL_FLAG_WRITE_ONLY);
    int64_t position = 0;
    const bool known = readable && TryReadControl(*absolute, position);
    if (!TryWriteControl(*automatic, 0)) {
      notes_.push_back(device_ + " refused to switch auto-focus off (" + ErrnoText(errno) +
                       "): the focus, and with it the focal length, may change under the calibration");
      return;
    }
    if (known && !TryWriteControl(*absolute, position)) {
      notes_.push_back(device_ + " refused to hold the focus at " + std::to_string(position) + " (" +
                       ErrnoText(errno) + ")");
    }
    return;
  }
  int64_t value = 0;
  ParseInteger(focus, value);  // checked by ValidateOptions
  if (absolute == nullptr) {
    notes_.push_back(device_ + " has no focus position control; --focus " + focus + " does nothing");
    return;
  }
  CheckRange(*absolute, value, "focus");  // before anything changes
  if (automatic != nullptr) WriteControl(*automatic, 0, "focus auto");
  WriteControl(*absolute, value, "focus");
}

void V4l2Source::ReadBackFocus() {
  const CameraControl* automatic = FindControl(V4L2_CID_FOCUS_AUTO);
  const CameraControl* absolute = FindControl(V4L2_CID_FOCUS_ABSOLUTE);
  int64_t value = 0;
  if (absolute != nullptr && !(absolute->flags & V4L2_CTRL_FLAG_WRITE_ONLY) && TryReadControl(*absolute, value))
    focus_position_ = value;
  int64_t automatic_on = 0;
  focus_held_ = automatic == nullptr || (TryReadControl(*automatic, automatic_on) && automatic_on == 0);
}

void V4l2Source::ApplyExposure() {
  const std::string& exposure = options_.exposure;
  const CameraControl* mode = FindControl(V4L2_CID_EXPOSURE_AUTO);
  const CameraControl* absolute = FindControl(V4L2_CID_EXPOSURE_ABSOLUTE);
  if (exposure == "auto") {
    if (mode == nullptr) return;  // the camera's own choice is automatic already: nothing to say
    const int64_t automatic = AutoExposureMode(*mode);
    if (mode->value_known && mode->value != V4L2_EXPOSURE_MANUAL) return;  // automatic already
    if (automatic < 0) {
      notes_.push_back(device_ + " offers no automatic exposure mode; exposure left as it is");
      return;
    }
    // The default: a camera that refuses gets a note, as for the focus lock.
    if (!TryWriteControl(*mode, automatic)) {
      notes_.push_back(device_ + " refused to switch automatic exposure on (" + ErrnoText(errno) + ")");
    }
    return;
  }
  if (mode == nullptr || absolute == nullptr) {
    notes_.push_back(device_ + " has no manual exposure control; --exposure " + exposure + " does nothing");
    return;
  }
  int64_t value = 0;
  const bool number = ParseInteger(exposure, value);
  if (number) CheckRange(*absolute, value, "exposure");  // before anything changes
  if (!number) value = ReadControl(*absolute);  // lock: the exposure time in use now
  WriteControl(*mode, V4L2_EXPOSURE_MANUAL, "exposure mode");
  WriteControl(*absolute, value, "exposure");
}

void V4l2Source::MapBuffers() {
  v4l2_requestbuffers req{};
  req.count = static_cast<uint32_t>(options_.buffer_count);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (Ioctl(VIDIOC_REQBUFS, &req) != 0) {
    if (errno == EBUSY) Fail("busy (another program is streaming from it)");
    Fail("does not support memory-mapped streaming (" + ErrnoText(errno) + ")");
  }
  if (req.count < 2) Fail("granted only " + std::to_string(req.count) + " streaming buffer(s); at least 2 are needed");
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (Ioctl(VIDIOC_QUERYBUF, &buf) != 0) Fail("cannot query streaming buffer " + std::to_string(i));
    void* start = io_.Mmap(buf.length, fd_, static_cast<off_t>(buf.m.offset));
    if (start == MAP_FAILED) Fail("cannot map streaming buffer " + std::to_string(i) + " (" + ErrnoText(errno) + ")");
    buffers_.push_back({start, buf.length});
  }
}

void V4l2Source::StartStreaming() {
  for (uint32_t i = 0; i < buffers_.size(); ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (Ioctl(VIDIOC_QBUF, &buf) != 0) Fail("cannot queue streaming buffer " + std::to_string(i) + " (" + ErrnoText(errno) + ")");
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(VIDIOC_STREAMON, &type) != 0) {
    if (errno == ENOSPC) Fail("not enough USB bandwidth for this size and format (try a smaller --size or MJPEG)");
    if (errno == ENODEV) Fail("device unplugged before streaming");
    Fail("cannot start streaming (" + ErrnoText(errno) + ")");
  }
  streaming_ = true;
}

void V4l2Source::Shutdown() {
  if (fd_ < 0) return;
  if (streaming_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    Ioctl(VIDIOC_STREAMOFF, &type);  // fails harmlessly when the device is gone
    streaming_ = false;
  }
  for (const Buffer& b : buffers_) io_.Munmap(b.start, b.length);
  buffers_.clear();
  io_.Close(fd_);
  fd_ = -1;
}

std::string V4l2Source::FormatName() const { return pixel_format_ == V4L2_PIX_FMT_YUYV ? "YUYV" : "MJPEG"; }

std::string V4l2Source::GrantedLine() const {
  std::string line = device_ + ": " + card_ + ", " + SizeText(width_, height_) + " " + FormatName() +
                     (granted_fps_ > 0 ? " at " + FpsText(granted_fps_) + " fps" : std::string(", rate not reported"));
  line += options_.fps > 0 ? " (asked " + FpsText(options_.fps) + ")" : " (the highest offered)";
  return line;
}

SourceCounts V4l2Source::Counts() const {
  SourceCounts counts;
  counts.driver_dropped = driver_dropped_.load();
  counts.corrupt_skipped = corrupt_skipped_.load();
  counts.stale_skipped = stale_skipped_.load();
  return counts;
}

// ---- V4l2Source: frames ----

void V4l2Source::CountSequence(uint32_t sequence) {
  // STREAMON starts the driver's count at 0, so frames before the first one dequeued were
  // dropped too. A number that does not increase (a driver restarting its count) is no gap.
  const int64_t expected = sequence_seen_ ? int64_t{last_sequence_} + 1 : 0;
  if (int64_t{sequence} > expected) driver_dropped_ += int64_t{sequence} - expected;
  if (!sequence_seen_ || sequence > last_sequence_) last_sequence_ = sequence;
  sequence_seen_ = true;
}

void V4l2Source::Requeue(v4l2_buffer& buffer) {
  if (Ioctl(VIDIOC_QBUF, &buffer) != 0) {
    const int err = errno;
    Shutdown();
    if (err == ENODEV) Fail("device unplugged during streaming; stopped");
    Fail("cannot requeue a buffer (" + ErrnoText(err) + "); stopped");
  }
}

bool V4l2Source::TakeNewest(v4l2_buffer& newest) {
  std::vector<v4l2_buffer> ready;
  for (;;) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    if (Ioctl(VIDIOC_DQBUF, &buf) != 0) {
      if (errno == EAGAIN) break;
      const int err = errno;
      Shutdown();
      if (err == ENODEV || err == EIO) Fail("device unplugged during streaming; stopped");
      Fail("cannot dequeue a frame (" + ErrnoText(err) + "); stopped");
    }
    if (buf.index >= buffers_.size()) {
      Shutdown();
      Fail("the driver returned buffer " + std::to_string(buf.index) + " of " + std::to_string(buffers_.size()) + "; stopped");
    }
    CountSequence(buf.sequence);
    ready.push_back(buf);
    if (!options_.newest_only) break;
  }
  // The newest one the driver did not flag; the others go back without being decoded.
  int keep = -1;
  for (int i = static_cast<int>(ready.size()) - 1; i >= 0 && keep < 0; --i) {
    if (!(ready[static_cast<size_t>(i)].flags & V4L2_BUF_FLAG_ERROR)) keep = i;
  }
  for (int i = 0; i < static_cast<int>(ready.size()); ++i) {
    if (i == keep) continue;
    if (ready[static_cast<size_t>(i)].flags & V4L2_BUF_FLAG_ERROR) {
      ++corrupt_skipped_;
    } else {
      ++stale_skipped_;
    }
    Requeue(ready[static_cast<size_t>(i)]);
  }
  if (keep < 0) return false;
  newest = ready[static_cast<size_t>(keep)];
  return true;
}

cv::Mat V4l2Source::Decode(const v4l2_buffer& buf) const {
  const Buffer& b = buffers_.at(buf.index);
  const auto* data = static_cast<const uint8_t*>(b.start);
  const size_t used = std::min<size_t>(buf.bytesused ? buf.bytesused : b.length, b.length);
  try {
    return pixel_format_ == V4L2_PIX_FMT_YUYV ? DecodeYuyv(data, used, width_, height_, stride_)
                                               : DecodeMjpeg(data, used, width_, height_);
  } catch (const SourceError&) {
    return {};  // a corrupt frame (a USB hiccup) is skipped like a flagged one
  }
}

bool V4l2Source::Next(Frame& frame) {
  if (fd_ < 0) return false;
  using Clock = std::chrono::steady_clock;
  if (!streaming_) {
    try {
      StartStreaming();
    } catch (...) {
      Shutdown();
      throw;
    }
  }
  // UVC cameras often need a second or two (auto exposure) before their first frame.
  const double timeout = delivered_ == 0 ? std::max(options_.timeout_seconds, kFirstFrameTimeout)
                                         : options_.timeout_seconds;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  for (;;) {
    if (options_.cancel.IsCancelled()) return false;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      Shutdown();
      Fail("no frame within " + FpsText(timeout) + " s (camera stalled or unplugged); stopped");
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = io_.Poll(&p, 1, static_cast<int>(std::min<long long>(left, 100)));
    if (r < 0) {
      if (errno == EINTR) continue;  // a signal: look at the token again
      const int err = errno;
      Shutdown();
      Fail("poll failed (" + ErrnoText(err) + ")");
    }
    if (r == 0) continue;
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) {
      Shutdown();
      Fail("device unplugged or failed during streaming; stopped");
    }
    v4l2_buffer buf{};
    if (!TakeNewest(buf)) continue;
    const Clock::time_point dequeued = Clock::now();
    cv::Mat image = Decode(buf);
    Requeue(buf);
    if (image.empty()) {
      ++corrupt_skipped_;
      continue;
    }
    frame.image = std::move(image);
    frame.index = buf.sequence;
    const bool monotonic = (buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    const bool stamped = buf.timestamp.tv_sec != 0 || buf.timestamp.tv_usec != 0;
    if (monotonic && stamped) {
      // libstdc++'s steady_clock reads CLOCK_MONOTONIC: the kernel's stamp is a time point on it.
      frame.capture_time = Clock::time_point(std::chrono::duration_cast<Clock::duration>(
          std::chrono::seconds(buf.timestamp.tv_sec) + std::chrono::microseconds(buf.timestamp.tv_usec)));
    } else {
      frame.capture_time = dequeued;  // a driver without capture timestamps: the best estimate left
    }
    frame.timestamp = (buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) != V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN && stamped
                          ? static_cast<double>(buf.timestamp.tv_sec) + 1e-6 * static_cast<double>(buf.timestamp.tv_usec)
                          : std::chrono::duration<double>(dequeued.time_since_epoch()).count();
    ++delivered_;
    return true;
  }
}

cv::Mat DecodeYuyv(const uint8_t* data, size_t bytes, int width, int height, int stride) {
  if (width <= 0 || height <= 0 || width % 2 != 0) {
    throw SourceError("YUYV frame: width must be positive and even, height positive (got " + std::to_string(width) +
                      "x" + std::to_string(height) + ")");
  }
  if (stride < 2 * width) throw SourceError("YUYV frame: row stride " + std::to_string(stride) + " is below 2 × width");
  const size_t needed = static_cast<size_t>(stride) * static_cast<size_t>(height - 1) + 2 * static_cast<size_t>(width);
  if (data == nullptr || bytes < needed) {
    throw SourceError("YUYV frame: " + std::to_string(bytes) + " bytes, " + std::to_string(needed) + " needed for " +
                      std::to_string(width) + "x" + std::to_string(height));
  }
  const cv::Mat packed(height, width, CV_8UC2, const_cast<uint8_t*>(data), static_cast<size_t>(stride));
  cv::Mat bgr;
  cv::cvtColor(packed, bgr, cv::COLOR_YUV2BGR_YUYV);
  return bgr;
}

cv::Mat DecodeMjpeg(const uint8_t* data, size_t bytes, int expected_width, int expected_height) {
  if (data == nullptr || bytes < 4 || data[0] != 0xFF || data[1] != 0xD8) {
    throw SourceError("MJPEG frame: not JPEG data (" + std::to_string(bytes) + " bytes, no start-of-image marker)");
  }
  if (bytes > static_cast<size_t>(std::numeric_limits<int>::max() / 2)) throw SourceError("MJPEG frame: too large");
  cv::Mat image;
  try {
    // Our libjpeg calls, not cv::imdecode: a damaged or cut frame (a USB hiccup) is refused with
    // libjpeg's reason, where imdecode printed libjpeg's warning and returned the damaged image
    // (or, for a cut frame, its missing part grey without a word). Padding before EOI is kept.
    image = DecodeJpeg(std::string_view(reinterpret_cast<const char*>(data), bytes), "MJPEG frame", cv::IMREAD_COLOR,
                       JpegDamage::kAcceptPaddingBeforeEnd);
  } catch (const Error& e) {
    throw SourceError(std::string(e.what()) + " (" + std::to_string(bytes) + " bytes)");
  }
  if (expected_width > 0 && (image.cols != expected_width || image.rows != expected_height)) {
    throw SourceError("MJPEG frame: decoded " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                      ", expected " + std::to_string(expected_width) + "x" + std::to_string(expected_height));
  }
  return image;
}

}  // namespace arview::recordings
