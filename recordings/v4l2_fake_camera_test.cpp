// V4l2Source against a simulated camera (V4l2Io): negotiation, mmap streaming, timestamps,
// corrupt frames, stalls, unplugging and clean shutdown, which no attached device can show here.

#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <chrono>
#include <cstring>
#include <deque>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recordings/recorder.h"
#include "recordings/test_helpers.h"
#include "recordings/v4l2_source.h"

namespace arview::recordings {
namespace {

// A frame size the fake camera lists, with its rates (frames per second, highest first).
struct FakeMode {
  uint32_t fourcc = 0;
  cv::Size size;
  std::vector<uint32_t> fps;
};

struct FakeControl {
  v4l2_queryctrl query{};
  int32_t value = 0;
  std::vector<uint32_t> menu;  // the menu indices QUERYMENU names (others: EINVAL, as UVC skips them)
};

struct FakeConfig {
  bool exists = true;
  bool char_device = true;
  int open_errno = 0;
  int sfmt_errno = 0;
  uint32_t caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<uint32_t> formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV};
  cv::Size native{64, 48};     // S_FMT answers with this size whatever is asked, when `modes` is empty
  // Sizes and rates to enumerate; empty: ENUM_FRAMESIZES answers EINVAL (an old driver).
  std::vector<FakeMode> modes;
  bool stepwise = false;       // ENUM_FRAMESIZES gives one stepwise range, intervals a continuous one
  bool parm = true;            // G_PARM and S_PARM answer (with V4L2_CAP_TIMEPERFRAME)
  std::vector<FakeControl> controls;
  int row_padding = 8;         // YUYV bytesperline = 2 × width + padding
  int unplug_after = -1;       // frames produced before the device vanishes (at the next one)
  int stall_after = -1;        // frames produced before the device stops sending
  int corrupt_frame = -1;      // this frame comes flagged V4L2_BUF_FLAG_ERROR
  uint32_t timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  bool refuse_writes = false;  // S_CTRL fails with EACCES (a read-only control, a camera that will not)
};

FakeControl Control(uint32_t id, const char* name, uint32_t type, int32_t min, int32_t max, int32_t step, int32_t def,
                    std::vector<uint32_t> menu = {}) {
  FakeControl c;
  c.query.id = id;
  std::strcpy(reinterpret_cast<char*>(c.query.name), name);
  c.query.type = type;
  c.query.minimum = min;
  c.query.maximum = max;
  c.query.step = step;
  c.query.default_value = def;
  c.value = def;
  c.menu = std::move(menu);
  return c;
}

// A UVC webcam's focus and exposure controls, as uvcvideo lists them (in id order, after the
// camera class), with auto-focus and aperture-priority exposure on.
std::vector<FakeControl> WebcamControls() {
  return {Control(V4L2_CID_CAMERA_CLASS, "Camera Controls", V4L2_CTRL_TYPE_CTRL_CLASS, 0, 0, 0, 0),
          Control(V4L2_CID_EXPOSURE_AUTO, "Auto Exposure", V4L2_CTRL_TYPE_MENU, 0, 3, 1, 3, {1, 3}),
          Control(V4L2_CID_EXPOSURE_ABSOLUTE, "Exposure Time, Absolute", V4L2_CTRL_TYPE_INTEGER, 3, 2047, 1, 250),
          Control(V4L2_CID_FOCUS_ABSOLUTE, "Focus, Absolute", V4L2_CTRL_TYPE_INTEGER, 0, 250, 5, 0),
          Control(V4L2_CID_FOCUS_AUTO, "Focus, Automatic Continuous", V4L2_CTRL_TYPE_BOOLEAN, 0, 1, 1, 1)};
}

// A USB 2 webcam: YUYV at 30 fps only up to 640x480, MJPEG at 30 everywhere.
std::vector<FakeMode> Usb2Modes() {
  return {{V4L2_PIX_FMT_MJPEG, {640, 480}, {30, 15}},
          {V4L2_PIX_FMT_MJPEG, {1280, 720}, {30, 15}},
          {V4L2_PIX_FMT_MJPEG, {1920, 1080}, {30, 15}},
          {V4L2_PIX_FMT_YUYV, {640, 480}, {30, 15}},
          {V4L2_PIX_FMT_YUYV, {1280, 720}, {10, 5}},
          {V4L2_PIX_FMT_YUYV, {1920, 1080}, {5}}};
}

// Frames arrive one per Poll (or as many as Arrive says), each into the next queued buffer;
// one that finds none is dropped and its sequence number skipped, as a driver does.
class FakeCamera : public V4l2Io {
 public:
  explicit FakeCamera(FakeConfig config) : c_(std::move(config)) {}

  int Stat(const char*, struct stat* st) override {
    if (!c_.exists) return Error(ENOENT);
    *st = {};
    st->st_mode = c_.char_device ? S_IFCHR : S_IFREG;
    return 0;
  }
  int Open(const char*, int) override {
    if (c_.open_errno) return Error(c_.open_errno);
    open_ = true;
    return kFd;
  }
  int Close(int fd) override {
    EXPECT_EQ(fd, kFd);
    open_ = false;
    return 0;
  }
  int Poll(pollfd* fds, nfds_t, int timeout_ms) override {
    EXPECT_EQ(fds[0].fd, kFd);
    if (Unplugged() || !streaming_) {
      fds[0].revents = POLLERR;
      return 1;
    }
    if (filled_.empty() && !Stalled()) Arrive(1);
    if (Unplugged()) {
      fds[0].revents = POLLERR;
      return 1;
    }
    if (filled_.empty()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms));
      return 0;
    }
    fds[0].revents = POLLIN;
    return 1;
  }
  void* Mmap(size_t length, int, off_t offset) override {
    const size_t i = static_cast<size_t>(offset) / kPage;
    if (i >= buffers_.size() || length != buffers_[i].size()) return MAP_FAILED;
    ++mapped_;
    return buffers_[i].data();
  }
  int Munmap(void*, size_t) override {
    --mapped_;
    return 0;
  }
  int Ioctl(int fd, unsigned long request, void* arg) override {
    EXPECT_EQ(fd, kFd);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        *cap = {};
        std::strcpy(reinterpret_cast<char*>(cap->card), "Fake camera");
        cap->capabilities = c_.caps | V4L2_CAP_DEVICE_CAPS;
        cap->device_caps = c_.caps;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        if (d->index >= c_.formats.size()) return Error(EINVAL);
        d->pixelformat = c_.formats[d->index];
        return 0;
      }
      case VIDIOC_ENUM_FRAMESIZES: return EnumSizes(static_cast<v4l2_frmsizeenum*>(arg));
      case VIDIOC_ENUM_FRAMEINTERVALS: return EnumIntervals(static_cast<v4l2_frmivalenum*>(arg));
      case VIDIOC_S_FMT: return SetFormat(static_cast<v4l2_format*>(arg)->fmt.pix);
      case VIDIOC_G_PARM:
      case VIDIOC_S_PARM: return Parm(request, static_cast<v4l2_streamparm*>(arg));
      case VIDIOC_QUERYCTRL: return QueryControl(static_cast<v4l2_queryctrl*>(arg));
      case VIDIOC_QUERYMENU: {
        auto* m = static_cast<v4l2_querymenu*>(arg);
        FakeControl* c = FindControl(m->id);
        if (c == nullptr || std::find(c->menu.begin(), c->menu.end(), m->index) == c->menu.end()) return Error(EINVAL);
        std::snprintf(reinterpret_cast<char*>(m->name), sizeof(m->name), "Mode %u", m->index);
        return 0;
      }
      case VIDIOC_G_CTRL: {
        auto* v = static_cast<v4l2_control*>(arg);
        FakeControl* c = FindControl(v->id);
        if (c == nullptr) return Error(EINVAL);
        v->value = c->value;
        return 0;
      }
      case VIDIOC_S_CTRL: return SetControl(static_cast<v4l2_control*>(arg));
      case VIDIOC_REQBUFS: {
        auto* req = static_cast<v4l2_requestbuffers*>(arg);
        req->count = std::min<uint32_t>(req->count, 3);
        buffers_.assign(req->count, std::vector<uint8_t>(sizeimage_));
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        b->length = static_cast<uint32_t>(buffers_.at(b->index).size());
        b->m.offset = b->index * kPage;
        return 0;
      }
      case VIDIOC_QBUF:
        if (Unplugged()) return Error(ENODEV);
        queue_.push_back(static_cast<v4l2_buffer*>(arg)->index);
        return 0;
      case VIDIOC_STREAMON:
        streaming_ = true;
        return 0;
      case VIDIOC_STREAMOFF:
        streaming_ = false;
        ++streamoffs_;
        return Unplugged() ? Error(ENODEV) : 0;
      case VIDIOC_DQBUF:
        return Dequeue(static_cast<v4l2_buffer*>(arg));
    }
    return Error(ENOTTY);
  }

  // `count` frames come from the sensor now, each into the next queued buffer or dropped.
  void Arrive(int count) {
    for (int i = 0; i < count; ++i) Produce();
  }

  bool open() const { return open_; }
  bool streaming() const { return streaming_; }
  int mapped() const { return mapped_; }
  int streamoffs() const { return streamoffs_; }
  uint32_t interval_denominator() const { return interval_.denominator; }
  int32_t control(uint32_t id) { return FindControl(id)->value; }
  const std::vector<std::pair<uint32_t, int32_t>>& writes() const { return writes_; }

 private:
  static constexpr int kFd = 42;
  static constexpr size_t kPage = 4096;
  static int Error(int err) {
    errno = err;
    return -1;
  }
  bool Unplugged() const { return unplugged_; }
  bool Stalled() const { return c_.stall_after >= 0 && produced_ >= c_.stall_after; }

  const FakeMode* Mode(uint32_t fourcc, cv::Size size) const {
    for (const FakeMode& m : c_.modes) {
      if (m.fourcc == fourcc && m.size == size) return &m;
    }
    return nullptr;
  }
  std::vector<const FakeMode*> Modes(uint32_t fourcc) const {
    std::vector<const FakeMode*> out;
    for (const FakeMode& m : c_.modes) {
      if (m.fourcc == fourcc) out.push_back(&m);
    }
    return out;
  }

  int EnumSizes(v4l2_frmsizeenum* fs) {
    if (c_.stepwise) {
      if (fs->index > 0) return Error(EINVAL);
      fs->type = V4L2_FRMSIZE_TYPE_STEPWISE;
      fs->stepwise = {160, 1920, 16, 120, 1080, 8};
      return 0;
    }
    const auto modes = Modes(fs->pixel_format);
    if (fs->index >= modes.size()) return Error(EINVAL);
    fs->type = V4L2_FRMSIZE_TYPE_DISCRETE;
    fs->discrete.width = static_cast<uint32_t>(modes[fs->index]->size.width);
    fs->discrete.height = static_cast<uint32_t>(modes[fs->index]->size.height);
    return 0;
  }
  int EnumIntervals(v4l2_frmivalenum* fi) {
    if (c_.stepwise) {
      if (fi->index > 0) return Error(EINVAL);
      fi->type = V4L2_FRMIVAL_TYPE_CONTINUOUS;
      fi->stepwise.min = {1, 60};
      fi->stepwise.max = {1, 5};
      fi->stepwise.step = {1, 1};
      return 0;
    }
    const FakeMode* m = Mode(fi->pixel_format, {static_cast<int>(fi->width), static_cast<int>(fi->height)});
    if (m == nullptr || fi->index >= m->fps.size()) return Error(EINVAL);
    fi->type = V4L2_FRMIVAL_TYPE_DISCRETE;
    fi->discrete = {1, m->fps[fi->index]};
    return 0;
  }
  int SetFormat(v4l2_pix_format& pix) {
    if (c_.sfmt_errno) return Error(c_.sfmt_errno);
    format_ = pix.pixelformat;
    size_ = c_.native;
    long best = -1;
    for (const FakeMode* m : Modes(format_)) {  // the nearest listed size, as a driver picks
      const long d = std::labs(long{m->size.width} - long{pix.width}) + std::labs(long{m->size.height} - long{pix.height});
      if (best < 0 || d < best) {
        best = d;
        size_ = m->size;
        interval_ = {1, m->fps.front()};  // a new size starts at its highest rate
      }
    }
    pix.width = static_cast<uint32_t>(size_.width);
    pix.height = static_cast<uint32_t>(size_.height);
    pix.bytesperline = format_ == V4L2_PIX_FMT_YUYV ? 2 * pix.width + c_.row_padding : 0;
    pix.sizeimage = format_ == V4L2_PIX_FMT_YUYV ? pix.bytesperline * pix.height : 65536;
    sizeimage_ = pix.sizeimage;
    return 0;
  }
  int Parm(unsigned long request, v4l2_streamparm* p) {
    if (!c_.parm) return Error(ENOTTY);
    if (request == VIDIOC_S_PARM) {
      // The offered rate nearest to the one asked.
      const double asked = double(p->parm.capture.timeperframe.denominator) / p->parm.capture.timeperframe.numerator;
      const FakeMode* m = Mode(format_, size_);
      if (m != nullptr) {
        uint32_t best = m->fps.front();
        for (uint32_t f : m->fps) {
          if (std::abs(f - asked) < std::abs(best - asked)) best = f;
        }
        interval_ = {1, best};
      } else {
        interval_ = p->parm.capture.timeperframe;
      }
    }
    p->parm.capture = {};
    p->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
    p->parm.capture.timeperframe = interval_;
    return 0;
  }
  FakeControl* FindControl(uint32_t id) {
    for (FakeControl& c : c_.controls) {
      if (c.query.id == id) return &c;
    }
    return nullptr;
  }
  int QueryControl(v4l2_queryctrl* q) {
    const bool next = q->id & V4L2_CTRL_FLAG_NEXT_CTRL;
    const uint32_t id = q->id & ~(V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND);
    for (const FakeControl& c : c_.controls) {
      if (next ? c.query.id > id : c.query.id == id) {
        *q = c.query;
        // As uvcvideo: the position controls are inactive while their automatic mode runs.
        const bool focus_auto = FindControl(V4L2_CID_FOCUS_AUTO) && FindControl(V4L2_CID_FOCUS_AUTO)->value == 1;
        const bool exposure_auto = FindControl(V4L2_CID_EXPOSURE_AUTO) && FindControl(V4L2_CID_EXPOSURE_AUTO)->value != 1;
        if ((c.query.id == V4L2_CID_FOCUS_ABSOLUTE && focus_auto) ||
            (c.query.id == V4L2_CID_EXPOSURE_ABSOLUTE && exposure_auto)) {
          q->flags |= V4L2_CTRL_FLAG_INACTIVE;
        }
        return 0;
      }
    }
    return Error(EINVAL);
  }
  int SetControl(v4l2_control* v) {
    FakeControl* c = FindControl(v->id);
    if (c == nullptr) return Error(EINVAL);
    if (c_.refuse_writes) return Error(EACCES);
    if (v->value < c->query.minimum || v->value > c->query.maximum) return Error(ERANGE);
    v4l2_queryctrl q{};
    q.id = v->id;
    QueryControl(&q);
    if (q.flags & V4L2_CTRL_FLAG_INACTIVE) return Error(EACCES);  // uvcvideo refuses inactive controls
    c->value = v->value;
    writes_.emplace_back(v->id, v->value);
    return 0;
  }

  void Produce() {
    if (c_.unplug_after >= 0 && produced_ >= c_.unplug_after) unplugged_ = true;  // instead of the next frame
    if (unplugged_) return;
    const int n = produced_++;
    if (queue_.empty()) return;  // no buffer: the frame is dropped, its number skipped
    const uint32_t index = queue_.front();
    queue_.pop_front();
    std::vector<uint8_t>& data = buffers_[index];
    v4l2_buffer b{};
    const cv::Mat bgr = test::MakeImage(size_.width, size_.height, n);
    if (format_ == V4L2_PIX_FMT_YUYV) {
      const std::vector<uint8_t> packed = test::PackYuyv(bgr, c_.row_padding);
      EXPECT_EQ(packed.size(), data.size());
      std::copy(packed.begin(), packed.end(), data.begin());
      b.bytesused = static_cast<uint32_t>(data.size());
    } else {
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
      EXPECT_LE(jpeg.size(), data.size());
      std::copy(jpeg.begin(), jpeg.begin() + std::min(jpeg.size(), data.size()), data.begin());
      b.bytesused = static_cast<uint32_t>(jpeg.size());
    }
    b.index = index;
    b.sequence = static_cast<uint32_t>(n);
    b.timestamp.tv_sec = 100 + n / 30;
    b.timestamp.tv_usec = (n % 30) * 1000000 / 30;
    b.flags = c_.timestamp_flags | (n == c_.corrupt_frame ? V4L2_BUF_FLAG_ERROR : 0);
    filled_.push_back(b);
  }

  int Dequeue(v4l2_buffer* b) {
    if (Unplugged()) return Error(ENODEV);
    if (!streaming_ || filled_.empty()) return Error(EAGAIN);
    *b = filled_.front();
    filled_.pop_front();
    return 0;
  }

  FakeConfig c_;
  bool open_ = false, streaming_ = false, unplugged_ = false;
  int mapped_ = 0, streamoffs_ = 0, produced_ = 0;
  uint32_t format_ = 0, sizeimage_ = 0;
  cv::Size size_;
  v4l2_fract interval_{1, 30};
  std::vector<std::vector<uint8_t>> buffers_;
  std::deque<uint32_t> queue_;     // queued by the reader, waiting for a frame
  std::deque<v4l2_buffer> filled_;  // filled, waiting to be dequeued
  std::vector<std::pair<uint32_t, int32_t>> writes_;  // every S_CTRL, in order
};

std::string OpenError(FakeConfig config, V4l2Options options = {}) {
  FakeCamera camera(std::move(config));
  try {
    V4l2Source source("/dev/video7", options, camera);
  } catch (const SourceError& e) {
    EXPECT_FALSE(camera.open()) << "the device must be closed after a failed open";
    EXPECT_EQ(camera.mapped(), 0);
    return e.what();
  }
  return "";
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(V4l2FakeCamera, StreamsYuyvWithKernelTimestampsAndTheDriversSize) {
  FakeCamera camera({});
  {
    V4l2Source source("/dev/video7", {}, camera);  // asks 640x480; the driver answers 64x48
    EXPECT_EQ(source.FormatName(), "YUYV");        // preferred over MJPEG when both are offered
    EXPECT_EQ(source.size(), cv::Size(64, 48));
    EXPECT_EQ(source.CardName(), "Fake camera");
    Frame f;
    for (int i = 0; i < 7; ++i) {  // more frames than buffers: requeueing works
      ASSERT_TRUE(source.Next(f));
      EXPECT_EQ(f.index, i);
      EXPECT_NEAR(f.timestamp, 100.0 + i / 30.0, 1e-5);
      ASSERT_EQ(f.image.size(), cv::Size(64, 48));
      // YUYV halves the chroma resolution: close to the source image, not identical.
      EXPECT_LT(cv::norm(f.image, test::MakeImage(64, 48, i), cv::NORM_L1) / (64 * 48 * 3), 3.0);
    }
  }
  EXPECT_EQ(camera.streamoffs(), 1);
  EXPECT_EQ(camera.mapped(), 0);
  EXPECT_FALSE(camera.open());
}

TEST(V4l2FakeCamera, FallsBackToMjpegOrUsesItWhenAsked) {
  FakeConfig only_mjpeg;
  only_mjpeg.formats = {V4L2_PIX_FMT_MJPEG};
  FakeCamera camera(only_mjpeg);
  V4l2Source source("/dev/video7", {}, camera);
  EXPECT_EQ(source.FormatName(), "MJPEG");
  Frame f;
  ASSERT_TRUE(source.Next(f));
  EXPECT_LT(cv::norm(f.image, test::MakeImage(64, 48, 0), cv::NORM_L1) / (64 * 48 * 3), 3.0);

  FakeCamera both({});
  V4l2Options options;
  options.format = "mjpeg";
  EXPECT_EQ(V4l2Source("/dev/video7", options, both).FormatName(), "MJPEG");
}

TEST(V4l2FakeCamera, EveryOpeningFailureIsOneMessageNamingTheDevice) {
  FakeConfig c;
  c.exists = false;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: no such device")) << OpenError(c);
  c = {};
  c.char_device = false;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: not a video device"));
  c = {};
  c.open_errno = EACCES;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: permission denied"));
  c = {};
  c.open_errno = EBUSY;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: busy"));
  c = {};
  c.sfmt_errno = EBUSY;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: busy"));
  c = {};
  c.caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: not a video capture device"));
  c = {};
  c.caps = V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: offers only the multi-planar capture API"));
  c = {};
  c.caps = V4L2_CAP_VIDEO_CAPTURE;
  EXPECT_TRUE(Contains(OpenError(c), "/dev/video7: does not support streaming"));
  c = {};
  c.formats = {V4L2_PIX_FMT_H264, V4L2_PIX_FMT_GREY};
  const std::string msg = OpenError(c);
  EXPECT_TRUE(Contains(msg, "/dev/video7: no supported pixel format")) << msg;
  EXPECT_TRUE(Contains(msg, "H264, GREY")) << msg;
  c = {};
  c.formats = {V4L2_PIX_FMT_MJPEG};
  V4l2Options yuyv;
  yuyv.format = "yuyv";
  EXPECT_TRUE(Contains(OpenError(c, yuyv), "arview reads yuyv"));
}

TEST(V4l2FakeCamera, UnpluggingIsReportedAtOnceAndStopsCleanly) {
  FakeConfig c;
  c.unplug_after = 3;
  FakeCamera camera(c);
  V4l2Source source("/dev/video7", {}, camera);
  Frame f;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(source.Next(f));
  const auto start = std::chrono::steady_clock::now();
  try {
    source.Next(f);
    FAIL() << "expected a SourceError";
  } catch (const SourceError& e) {
    EXPECT_TRUE(Contains(e.what(), "/dev/video7: device unplugged")) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  EXPECT_FALSE(camera.open());
  EXPECT_EQ(camera.mapped(), 0);
  EXPECT_FALSE(source.Next(f));  // stays stopped
}

TEST(V4l2FakeCamera, AStalledCameraIsReportedAfterTheTimeout) {
  FakeConfig c;
  c.stall_after = 2;
  FakeCamera camera(c);
  V4l2Options options;
  options.timeout_seconds = 0.3;
  V4l2Source source("/dev/video7", options, camera);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  ASSERT_TRUE(source.Next(f));
  const auto start = std::chrono::steady_clock::now();
  try {
    source.Next(f);
    FAIL() << "expected a SourceError";
  } catch (const SourceError& e) {
    EXPECT_TRUE(Contains(e.what(), "/dev/video7: no frame within 0.3 s")) << e.what();
  }
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.3 - 1e-3);
  EXPECT_FALSE(camera.open());
}

TEST(V4l2FakeCamera, SkipsCorruptFramesAndHonoursTheStopFlag) {
  FakeConfig c;
  c.corrupt_frame = 1;
  FakeCamera camera(c);
  V4l2Options options;
  V4l2Source source("/dev/video7", options, camera);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  EXPECT_EQ(f.index, 0);
  ASSERT_TRUE(source.Next(f));
  EXPECT_EQ(f.index, 2);
  EXPECT_EQ(source.skipped_frames(), 1);
  EXPECT_EQ(source.Counts().corrupt_skipped, 1);
  EXPECT_EQ(source.Counts().driver_dropped, 0);  // the flagged frame has its number: no gap
  options.cancel.Cancel(SIGINT);  // the source holds a copy of the token: the same state
  EXPECT_FALSE(source.Next(f));
}

TEST(V4l2FakeCamera, RecordingUntilUnplugKeepsAValidRecording) {
  FakeConfig c;
  c.unplug_after = 10;
  FakeCamera camera(c);
  test::TempDir dir("v4l2_record");
  V4l2Source source("/dev/video7", {}, camera);
  RecordingWriter writer(dir.path() / "rec", calib::Camera::Pinhole(64, 48, 60, 60, 31.5, 23.5), false);
  EXPECT_THROW(RecordFrames(source, writer, 0, {}), SourceError);
  const Recording rec = LoadRecording(dir.path() / "rec");
  ASSERT_EQ(rec.frames.size(), 10u);
  EXPECT_DOUBLE_EQ(rec.frames[0].timestamp, 0.0);
  EXPECT_NEAR(rec.frames[9].timestamp, 9 / 30.0, 1e-5);
  EXPECT_EQ(rec.ReadImage(9).size(), cv::Size(64, 48));
}

// ---- Camera set-up (issue 35, item 2) ----

FakeConfig Usb2Webcam() {
  FakeConfig c;
  c.modes = Usb2Modes();
  c.controls = WebcamControls();
  return c;
}

V4l2Options Asking(int width, int height, double fps, const std::string& format = "auto") {
  V4l2Options o;
  o.width = width;
  o.height = height;
  o.fps = fps;
  o.format = format;
  return o;
}

TEST(V4l2FakeCamera, EnumeratesFormatsSizesAndRates) {
  FakeCamera camera(Usb2Webcam());
  const CameraInfo info = DescribeCamera("/dev/video7", camera);
  EXPECT_FALSE(camera.open());
  EXPECT_FALSE(camera.streaming());
  EXPECT_EQ(info.card, "Fake camera");
  ASSERT_EQ(info.capabilities.formats.size(), 2u);
  const FormatCapabilities* mjpeg = info.capabilities.Find(V4L2_PIX_FMT_MJPEG);
  const FormatCapabilities* yuyv = info.capabilities.Find(V4L2_PIX_FMT_YUYV);
  ASSERT_TRUE(mjpeg && yuyv);
  EXPECT_EQ(mjpeg->name, "MJPG");
  ASSERT_EQ(mjpeg->sizes.size(), 3u);
  EXPECT_EQ(mjpeg->sizes[1].width, 1280);
  EXPECT_EQ(mjpeg->sizes[1].height, 720);
  EXPECT_EQ(mjpeg->sizes[1].fps, (std::vector<double>{30, 15}));
  EXPECT_DOUBLE_EQ(info.capabilities.MaxFps(V4L2_PIX_FMT_YUYV, {640, 480}), 30);
  EXPECT_DOUBLE_EQ(info.capabilities.MaxFps(V4L2_PIX_FMT_YUYV, {1280, 720}), 10);
  EXPECT_DOUBLE_EQ(info.capabilities.MaxFps(V4L2_PIX_FMT_YUYV, {1920, 1080}), 5);
  EXPECT_DOUBLE_EQ(info.capabilities.MaxFps(V4L2_PIX_FMT_YUYV, {800, 600}), 0);  // not listed
  EXPECT_EQ(info.capabilities.NearestSize(V4L2_PIX_FMT_YUYV, {1200, 700}), cv::Size(1280, 720));
  EXPECT_DOUBLE_EQ(info.current_fps, 30);
}

TEST(V4l2FakeCamera, AStepwiseRangeIsListedAtItsEndsAndTheCommonSizesInside) {
  FakeConfig c;
  c.stepwise = true;
  FakeCamera camera(c);
  const CameraInfo info = DescribeCamera("/dev/video7", camera);
  const FormatCapabilities* yuyv = info.capabilities.Find(V4L2_PIX_FMT_YUYV);
  ASSERT_TRUE(yuyv);
  EXPECT_TRUE(yuyv->stepwise_sizes);
  EXPECT_EQ(yuyv->min_size, cv::Size(160, 120));
  EXPECT_EQ(yuyv->max_size, cv::Size(1920, 1080));
  std::vector<cv::Size> sizes;
  for (const auto& s : yuyv->sizes) sizes.emplace_back(s.width, s.height);
  EXPECT_EQ(sizes, (std::vector<cv::Size>{{160, 120}, {640, 480}, {1280, 720}, {1920, 1080}}));
  EXPECT_TRUE(yuyv->sizes[0].continuous_rates);
  EXPECT_EQ(yuyv->sizes[0].fps, (std::vector<double>{60, 5}));
}

TEST(V4l2FakeCamera, AutoTakesYuyvOnlyWhereItReachesTheRateElseMjpeg) {
  struct Case {
    int width, height;
    double fps;
    const char* format;
    double granted;
  };
  for (const Case& k : {Case{640, 480, 0, "YUYV", 30}, Case{1280, 720, 0, "MJPEG", 30}, Case{1280, 720, 30, "MJPEG", 30},
                        Case{1280, 720, 10, "YUYV", 10}, Case{1920, 1080, 0, "MJPEG", 30},
                        Case{1920, 1080, 5, "YUYV", 5}}) {
    FakeCamera camera(Usb2Webcam());
    V4l2Source source("/dev/video7", Asking(k.width, k.height, k.fps), camera);
    const std::string label = std::to_string(k.width) + "x" + std::to_string(k.height) + " at " + std::to_string(k.fps);
    EXPECT_EQ(source.FormatName(), k.format) << label;
    EXPECT_EQ(source.size(), cv::Size(k.width, k.height)) << label;
    EXPECT_DOUBLE_EQ(source.fps(), k.granted) << label;
    EXPECT_EQ(camera.interval_denominator(), static_cast<uint32_t>(k.granted)) << label;  // set, not assumed
  }
}

TEST(V4l2FakeCamera, TheGrantedRateIsReadBackAndALowerOneIsSaid) {
  FakeCamera camera(Usb2Webcam());
  V4l2Source yuyv("/dev/video7", Asking(1280, 720, 30, "yuyv"), camera);
  EXPECT_DOUBLE_EQ(yuyv.fps(), 10);
  EXPECT_EQ(yuyv.GrantedLine(), "/dev/video7: Fake camera, 1280x720 YUYV at 10 fps (asked 30)");
  ASSERT_EQ(yuyv.notes().size(), 1u);
  EXPECT_TRUE(Contains(yuyv.notes()[0], "asked 30 fps, granted 10; YUYV at 1280x720 offers at most 10 fps"))
      << yuyv.notes()[0];
  EXPECT_TRUE(Contains(yuyv.notes()[0], "--format mjpeg")) << yuyv.notes()[0];

  FakeCamera second(Usb2Webcam());
  V4l2Source mjpeg("/dev/video7", Asking(640, 480, 15, "mjpeg"), second);
  EXPECT_DOUBLE_EQ(mjpeg.fps(), 15);
  EXPECT_EQ(second.interval_denominator(), 15u);
  EXPECT_EQ(mjpeg.GrantedLine(), "/dev/video7: Fake camera, 640x480 MJPEG at 15 fps (asked 15)");

  FakeCamera third(Usb2Webcam());
  EXPECT_EQ(V4l2Source("/dev/video7", Asking(640, 480, 0), third).GrantedLine(),
            "/dev/video7: Fake camera, 640x480 YUYV at 30 fps (the highest offered)");
}

TEST(V4l2FakeCamera, ACameraThatCannotSetItsRateSaysSoAndStillStreams) {
  FakeConfig c = Usb2Webcam();
  c.parm = false;
  FakeCamera camera(c);
  V4l2Source source("/dev/video7", Asking(640, 480, 30), camera);
  EXPECT_DOUBLE_EQ(source.fps(), 0);
  ASSERT_FALSE(source.notes().empty());
  EXPECT_TRUE(Contains(source.notes()[0], "does not let the frame rate be set")) << source.notes()[0];
  Frame f;
  EXPECT_TRUE(source.Next(f));
}

TEST(V4l2FakeCamera, ControlsAreListedWithRangesMenusAndValues) {
  FakeCamera camera(Usb2Webcam());
  const CameraInfo info = DescribeCamera("/dev/video7", camera);
  ASSERT_EQ(info.controls.size(), 4u);  // the class heading is not a control
  const CameraControl& exposure_auto = info.controls[0];
  EXPECT_EQ(exposure_auto.name, "Auto Exposure");
  EXPECT_EQ(exposure_auto.TypeName(), "menu");
  ASSERT_EQ(exposure_auto.menu.size(), 2u);  // the entries the driver names, not min..max
  EXPECT_EQ(exposure_auto.menu[0].value, 1);
  EXPECT_EQ(exposure_auto.menu[1].value, 3);
  EXPECT_TRUE(exposure_auto.value_known);
  EXPECT_EQ(exposure_auto.value, 3);
  const CameraControl& focus = info.controls[2];
  EXPECT_EQ(focus.name, "Focus, Absolute");
  EXPECT_EQ(focus.minimum, 0);
  EXPECT_EQ(focus.maximum, 250);
  EXPECT_EQ(focus.step, 5);
  EXPECT_TRUE(focus.Inactive());  // auto-focus is on
  EXPECT_EQ(info.controls[3].TypeName(), "bool");
}

TEST(V4l2FakeCamera, TheDefaultLocksFocusWhereItStandsAndLeavesExposureAutomatic) {
  FakeConfig c = Usb2Webcam();
  c.controls[3].value = 40;  // where auto-focus has put the lens
  FakeCamera camera(c);
  V4l2Source source("/dev/video7", {}, camera);
  EXPECT_TRUE(source.notes().empty());
  EXPECT_EQ(camera.control(V4L2_CID_FOCUS_AUTO), 0);
  EXPECT_EQ(camera.control(V4L2_CID_FOCUS_ABSOLUTE), 40);
  // Exposure automatic already: left alone.
  const std::vector<std::pair<uint32_t, int32_t>> writes = {{V4L2_CID_FOCUS_AUTO, 0}, {V4L2_CID_FOCUS_ABSOLUTE, 40}};
  EXPECT_EQ(camera.writes(), writes);

  // Exposure left manual by another program: the default switches it back to automatic,
  // aperture priority (UVC's automatic mode: its menu has no V4L2_EXPOSURE_AUTO).
  FakeConfig manual = Usb2Webcam();
  manual.controls[1].value = V4L2_EXPOSURE_MANUAL;
  FakeCamera second(manual);
  V4l2Source other("/dev/video7", {}, second);
  EXPECT_EQ(second.control(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_APERTURE_PRIORITY);
}

TEST(V4l2FakeCamera, ACameraThatRefusesTheFocusLockGetsANoteNotAnError) {
  FakeConfig c = Usb2Webcam();
  c.refuse_writes = true;
  FakeCamera camera(c);
  V4l2Source source("/dev/video7", {}, camera);
  ASSERT_EQ(source.notes().size(), 1u);
  EXPECT_TRUE(Contains(source.notes()[0], "/dev/video7 refused to switch auto-focus off (Permission denied)"))
      << source.notes()[0];
  V4l2Options o;
  o.focus = "auto";  // asked for explicitly: an error
  FakeCamera second(c);
  try {
    V4l2Source("/dev/video7", o, second);
    FAIL() << "expected a SourceError";
  } catch (const SourceError& e) {
    EXPECT_TRUE(Contains(e.what(), "/dev/video7: cannot set control 'Focus, Automatic Continuous' to 1")) << e.what();
  }
}

TEST(V4l2FakeCamera, AFocusNumberAndAnExposureLockSetTheControls) {
  FakeCamera camera(Usb2Webcam());
  V4l2Options o;
  o.focus = "120";
  o.exposure = "lock";
  V4l2Source source("/dev/video7", o, camera);
  EXPECT_EQ(camera.control(V4L2_CID_FOCUS_AUTO), 0);
  EXPECT_EQ(camera.control(V4L2_CID_FOCUS_ABSOLUTE), 120);
  EXPECT_EQ(camera.control(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(camera.control(V4L2_CID_EXPOSURE_ABSOLUTE), 250);  // the time in use when locked

  FakeCamera second(Usb2Webcam());
  o.focus = "auto";
  o.exposure = "800";
  V4l2Source other("/dev/video7", o, second);
  EXPECT_EQ(second.control(V4L2_CID_FOCUS_AUTO), 1);
  EXPECT_EQ(second.control(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(second.control(V4L2_CID_EXPOSURE_ABSOLUTE), 800);
}

TEST(V4l2FakeCamera, AValueOutsideAControlsRangeIsOneErrorNamingDeviceControlAndRange) {
  V4l2Options o;
  o.focus = "300";
  std::string msg = OpenError(Usb2Webcam(), o);
  EXPECT_TRUE(Contains(msg, "/dev/video7: focus 300 is outside the range of control 'Focus, Absolute' (0..250, step 5)"))
      << msg;
  o = {};
  o.exposure = "5000";
  msg = OpenError(Usb2Webcam(), o);
  EXPECT_TRUE(Contains(msg, "/dev/video7: exposure 5000 is outside the range of control 'Exposure Time, Absolute' (3..2047"))
      << msg;
  o = {};
  o.focus = "near";
  EXPECT_TRUE(Contains(OpenError(Usb2Webcam(), o), "/dev/video7: focus 'near' is not keep, auto, lock or a whole number"));
  // Refused before anything was changed on the camera.
  FakeCamera camera(Usb2Webcam());
  o = {};
  o.focus = "-5";
  EXPECT_THROW(V4l2Source("/dev/video7", o, camera), SourceError);
  EXPECT_TRUE(camera.writes().empty());
}

// Issue 57: a focus off the control's step (7 on a step of 5) was taken silently, and the driver
// held the lens at another position than the one asked for.
TEST(V4l2FakeCamera, AFocusBetweenTheControlsStepsIsRefusedNamingTheNearestPositions) {
  V4l2Options o;
  o.focus = "7";
  FakeCamera camera(Usb2Webcam());
  try {
    V4l2Source("/dev/video7", o, camera);
    FAIL() << "focus 7 was taken";
  } catch (const SourceError& e) {
    EXPECT_TRUE(Contains(e.what(), "/dev/video7: focus 7 is between the steps of control 'Focus, Absolute' (0..250, "
                                   "step 5): the camera holds 5 or 10"))
        << e.what();
  }
  EXPECT_TRUE(camera.writes().empty());  // refused before anything was changed
  o.focus = "249";
  EXPECT_TRUE(Contains(OpenError(Usb2Webcam(), o), "focus 249 is between the steps of control 'Focus, Absolute' "
                                                   "(0..250, step 5): the camera holds 245 or 250"));
  o.focus = "245";
  FakeCamera on_step(Usb2Webcam());
  V4l2Source source("/dev/video7", o, on_step);
  EXPECT_EQ(on_step.control(V4L2_CID_FOCUS_ABSOLUTE), 245);
}

TEST(V4l2FakeCamera, ACameraWithoutTheControlsSaysSoInOneNoteEach) {
  FakeConfig c = Usb2Webcam();
  c.controls.clear();
  FakeCamera camera(c);
  V4l2Options o;
  o.exposure = "lock";
  V4l2Source source("/dev/video7", o, camera);
  ASSERT_EQ(source.notes().size(), 2u);
  EXPECT_TRUE(Contains(source.notes()[0], "/dev/video7 has no auto-focus control")) << source.notes()[0];
  EXPECT_TRUE(Contains(source.notes()[1], "/dev/video7 has no manual exposure control")) << source.notes()[1];
  FakeCamera quiet(c);  // the defaults on a camera without controls: only the focus is worth a word
  EXPECT_EQ(V4l2Source("/dev/video7", {}, quiet).notes().size(), 1u);
}

TEST(V4l2FakeCamera, StreamingStartsAtTheFirstFrameAskedFor) {
  FakeCamera camera({});
  V4l2Source source("/dev/video7", {}, camera);
  EXPECT_FALSE(camera.streaming());
  EXPECT_FALSE(source.streaming());
  EXPECT_EQ(camera.mapped(), 3);  // buffers mapped in the constructor: errors come early
  Frame f;
  ASSERT_TRUE(source.Next(f));
  EXPECT_TRUE(camera.streaming());
  EXPECT_EQ(f.index, 0);
}

TEST(V4l2FakeCamera, TheNewestOfSeveralReadyFramesIsKeptAndTheOlderCountedStale) {
  FakeCamera camera({});
  V4l2Source source("/dev/video7", {}, camera);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  camera.Arrive(3);  // three frames wait in the three buffers
  ASSERT_TRUE(source.Next(f));
  EXPECT_EQ(f.index, 3);
  EXPECT_LT(cv::norm(f.image, test::MakeImage(64, 48, 3), cv::NORM_L1) / (64 * 48 * 3), 3.0);  // its own picture
  EXPECT_EQ(source.Counts().stale_skipped, 2);
  EXPECT_EQ(source.Counts().driver_dropped, 0);
  ASSERT_TRUE(source.Next(f));  // the older buffers went back: streaming goes on
  EXPECT_EQ(f.index, 4);
}

TEST(V4l2FakeCamera, WithoutNewestOnlyEveryFrameTheBuffersHoldComesInOrder) {
  FakeCamera camera({});
  V4l2Options o;
  o.newest_only = false;  // a recording
  V4l2Source source("/dev/video7", o, camera);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  camera.Arrive(3);
  for (int i = 1; i <= 3; ++i) {
    ASSERT_TRUE(source.Next(f));
    EXPECT_EQ(f.index, i);
  }
  EXPECT_EQ(source.Counts().stale_skipped, 0);
}

TEST(V4l2FakeCamera, GapsInTheSequenceAreCountedAsDriverDrops) {
  FakeCamera camera({});
  V4l2Source source("/dev/video7", {}, camera);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  camera.Arrive(5);  // three buffers: frames 1-3 fill them, 4 and 5 find none and are dropped
  ASSERT_TRUE(source.Next(f));
  EXPECT_EQ(f.index, 3);
  ASSERT_TRUE(source.Next(f));
  EXPECT_EQ(f.index, 6);
  const SourceCounts counts = source.Counts();
  EXPECT_EQ(counts.driver_dropped, 2);
  EXPECT_EQ(counts.stale_skipped, 2);
  EXPECT_EQ(counts.corrupt_skipped, 0);
}

TEST(V4l2FakeCamera, CaptureTimeIsTheKernelsMonotonicStampOrElseTheDequeueTime) {
  FakeCamera camera({});
  V4l2Source source("/dev/video7", {}, camera);
  Frame f;
  ASSERT_TRUE(source.Next(f));
  ASSERT_TRUE(source.Next(f));
  EXPECT_EQ(f.capture_time.time_since_epoch(),
            std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::microseconds(100033333)));

  FakeConfig c;
  c.timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
  FakeCamera unstamped(c);
  V4l2Source other("/dev/video7", {}, unstamped);
  const auto before = std::chrono::steady_clock::now();
  ASSERT_TRUE(other.Next(f));
  EXPECT_GE(f.capture_time, before);
  EXPECT_LE(f.capture_time, std::chrono::steady_clock::now());
}

TEST(V4l2FakeCamera, CountsCanBeReadWhileAnotherThreadTakesFrames) {
  FakeCamera camera({});
  V4l2Source source("/dev/video7", {}, camera);
  Frame first;
  ASSERT_TRUE(source.Next(first));  // streaming: the buffers are queued
  std::atomic<bool> done{false};
  std::thread reader([&] {
    Frame f;
    for (int i = 0; i < 30; ++i) {
      camera.Arrive(2);  // one stale frame each time
      source.Next(f);
    }
    done = true;
  });
  int64_t last = 0;
  while (!done) {
    const int64_t now = source.Counts().stale_skipped;
    EXPECT_GE(now, last);  // never goes back
    last = now;
  }
  reader.join();
  EXPECT_EQ(source.Counts().stale_skipped, 30);
}

TEST(V4l2FakeCamera, ListCamerasNamesTheVideoNodesInNumberOrder) {
  test::TempDir dir("v4l2_list");
  for (const char* name : {"video10", "video2", "video0", "videoX", "media0", "video"}) test::WriteFile(dir.path() / name, "");
  FakeConfig metadata;
  metadata.caps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
  FakeCamera camera(metadata);
  const std::vector<CameraListing> list = ListCameras(dir.path(), camera);
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0].device, (dir.path() / "video0").string());
  EXPECT_EQ(list[1].device, (dir.path() / "video2").string());
  EXPECT_EQ(list[2].device, (dir.path() / "video10").string());
  EXPECT_EQ(list[0].card, "Fake camera");
  EXPECT_FALSE(list[0].capture);  // a metadata node
  EXPECT_TRUE(list[0].problem.empty());
  EXPECT_FALSE(camera.open());

  FakeConfig busy;
  busy.open_errno = EBUSY;
  FakeCamera in_use(busy);
  const std::vector<CameraListing> busy_list = ListCameras(dir.path(), in_use);
  ASSERT_EQ(busy_list.size(), 3u);
  EXPECT_EQ(busy_list[0].problem.rfind("busy", 0), 0u) << busy_list[0].problem;
}

}  // namespace
}  // namespace arview::recordings
