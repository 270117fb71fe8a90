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
#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/jpeg_decoder.h"

namespace arview::recordings {

namespace {

class SystemIo : public V4l2Io {
 public:
  int Stat(const char* path, struct stat* st) override { return ::stat(path, st); }
  int Open(const char* path, int flags) override { return ::open(path, flags); }
  int Close(int fd) override { return ::close(fd); }
  int Ioctl(int fd, unsigned long request, void* arg) override { return ::ioctl(fd, request, arg); }
  int Poll(pollfd* fds, nfds_t count, int timeout_ms) override { return ::poll(fds, count, timeout_ms); }
  void* Mmap(size_t length, int fd, off_t offset) override {
    return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  }
  int Munmap(void* address, size_t length) override { return ::munmap(address, length); }
};

std::string FourccName(uint32_t f) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((f >> (8 * i)) & 0xff);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

std::string ErrnoText(int err) { return std::strerror(err); }

}  // namespace

V4l2Io& SystemV4l2Io() {
  static SystemIo io;
  return io;
}

int V4l2Source::Ioctl(unsigned long request, void* arg) {
  int r;
  do {
    r = io_.Ioctl(fd_, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

void V4l2Source::Fail(const std::string& problem) const { throw SourceError(device_ + ": " + problem); }

V4l2Source::V4l2Source(const std::string& device, V4l2Options options, V4l2Io& io)
    : device_(device), options_(std::move(options)), io_(io) {
  if (options_.width <= 0 || options_.height <= 0) Fail("requested frame size must be positive");
  if (options_.buffer_count < 2 || options_.buffer_count > 32) Fail("buffer count must be between 2 and 32");
  if (!(options_.timeout_seconds > 0)) Fail("frame timeout must be positive");
  if (options_.format != "auto" && options_.format != "yuyv" && options_.format != "mjpeg") {
    Fail("pixel format '" + options_.format + "' is not auto, yuyv or mjpeg");
  }
  struct stat st {};
  if (io_.Stat(device_.c_str(), &st) != 0) {
    if (errno == ENOENT) Fail("no such device (is the camera plugged in? see 'ls /dev/video*')");
    Fail("cannot be inspected (" + ErrnoText(errno) + ")");
  }
  if (!S_ISCHR(st.st_mode)) Fail("not a video device (not a character device)");
  fd_ = io_.Open(device_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int err = errno;
    if (err == EACCES) Fail("permission denied (add the user to the 'video' group)");
    if (err == EBUSY) Fail("busy (another program is using the camera)");
    if (err == ENODEV || err == ENXIO) Fail("no such device (unplugged?)");
    Fail("cannot be opened (" + ErrnoText(err) + ")");
  }
  try {
    QueryCapabilities();
    NegotiateFormat();
    StartStreaming();
  } catch (...) {
    Shutdown();
    throw;
  }
}

V4l2Source::~V4l2Source() { Shutdown(); }

void V4l2Source::QueryCapabilities() {
  v4l2_capability cap{};
  if (Ioctl(VIDIOC_QUERYCAP, &cap) != 0) {
    if (errno == ENOTTY || errno == EINVAL) Fail("not a V4L2 video device");
    if (errno == ENODEV) Fail("no such device (unplugged?)");
    Fail("capability query failed (" + ErrnoText(errno) + ")");
  }
  card_ = reinterpret_cast<const char*>(cap.card);
  const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE)) {
    Fail("offers only the multi-planar capture API, which arview does not read ('" + card_ + "')");
  }
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
    Fail("not a video capture device ('" + card_ + "'; a webcam usually has several /dev/video nodes, try another)");
  }
  if (!(caps & V4L2_CAP_STREAMING)) Fail("does not support streaming I/O ('" + card_ + "')");
}

void V4l2Source::NegotiateFormat() {
  std::vector<uint32_t> offered;
  for (uint32_t i = 0;; ++i) {
    v4l2_fmtdesc desc{};
    desc.index = i;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (Ioctl(VIDIOC_ENUM_FMT, &desc) != 0) break;
    offered.push_back(desc.pixelformat);
  }
  auto has = [&](uint32_t f) { return std::find(offered.begin(), offered.end(), f) != offered.end(); };
  std::vector<uint32_t> wanted;
  if (options_.format != "mjpeg") wanted.push_back(V4L2_PIX_FMT_YUYV);
  if (options_.format != "yuyv") {
    wanted.push_back(V4L2_PIX_FMT_MJPEG);
    wanted.push_back(V4L2_PIX_FMT_JPEG);
  }
  uint32_t chosen = 0;
  for (uint32_t f : wanted) {
    if (has(f)) {
      chosen = f;
      break;
    }
  }
  if (chosen == 0) {
    std::string list;
    for (uint32_t f : offered) list += (list.empty() ? "" : ", ") + FourccName(f);
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
    Fail("cannot set format " + FourccName(chosen) + " " + std::to_string(options_.width) + "x" +
         std::to_string(options_.height) + " (" + ErrnoText(errno) + ")");
  }
  if (fmt.fmt.pix.pixelformat != chosen) {
    Fail("the driver replaced format " + FourccName(chosen) + " with " + FourccName(fmt.fmt.pix.pixelformat));
  }
  pixel_format_ = chosen;
  width_ = static_cast<int>(fmt.fmt.pix.width);
  height_ = static_cast<int>(fmt.fmt.pix.height);
  stride_ = static_cast<int>(fmt.fmt.pix.bytesperline);
  if (pixel_format_ == V4L2_PIX_FMT_YUYV && stride_ < 2 * width_) stride_ = 2 * width_;
}

void V4l2Source::StartStreaming() {
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
    if (Ioctl(VIDIOC_QBUF, &buf) != 0) Fail("cannot queue streaming buffer " + std::to_string(i));
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(VIDIOC_STREAMON, &type) != 0) {
    if (errno == ENOSPC) Fail("not enough USB bandwidth for this size and format (try a smaller --size or MJPEG)");
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

bool V4l2Source::Next(Frame& frame) {
  if (fd_ < 0) return false;
  using Clock = std::chrono::steady_clock;
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
      char seconds[32];
      std::snprintf(seconds, sizeof(seconds), "%g", timeout);
      Fail(std::string("no frame within ") + seconds + " s (camera stalled or unplugged); stopped");
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
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    if (Ioctl(VIDIOC_DQBUF, &buf) != 0) {
      if (errno == EAGAIN) continue;
      const int err = errno;
      Shutdown();
      if (err == ENODEV || err == EIO) Fail("device unplugged during streaming; stopped");
      Fail("cannot dequeue a frame (" + ErrnoText(err) + "); stopped");
    }
    const Buffer& b = buffers_.at(buf.index);
    const auto* data = static_cast<const uint8_t*>(b.start);
    const size_t used = std::min<size_t>(buf.bytesused ? buf.bytesused : b.length, b.length);
    cv::Mat image;
    if (!(buf.flags & V4L2_BUF_FLAG_ERROR)) {
      try {
        image = pixel_format_ == V4L2_PIX_FMT_YUYV ? DecodeYuyv(data, used, width_, height_, stride_)
                                                   : DecodeMjpeg(data, used, width_, height_);
      } catch (const SourceError&) {
        image.release();  // a corrupt frame (USB hiccup) is skipped like a flagged one
      }
    }
    if (Ioctl(VIDIOC_QBUF, &buf) != 0) {
      const int err = errno;
      Shutdown();
      Fail("cannot requeue a buffer (" + ErrnoText(err) + "); stopped");
    }
    if (image.empty()) {
      ++skipped_;
      continue;
    }
    frame.image = std::move(image);
    frame.timestamp = static_cast<double>(buf.timestamp.tv_sec) + 1e-6 * static_cast<double>(buf.timestamp.tv_usec);
    if ((buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN || frame.timestamp == 0) {
      // A driver without capture timestamps: the dequeue time is the best estimate left.
      frame.timestamp = std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
    }
    frame.index = buf.sequence;
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
