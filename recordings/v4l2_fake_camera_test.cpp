// V4l2Source against a simulated camera (V4l2Io): negotiation, mmap streaming, timestamps,
// corrupt frames, stalls, unplugging and clean shutdown, which no attached device can show here.

#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
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

struct FakeConfig {
  bool exists = true;
  bool char_device = true;
  int open_errno = 0;
  int sfmt_errno = 0;
  uint32_t caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<uint32_t> formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV};
  cv::Size native{64, 48};     // S_FMT answers with this size whatever is asked
  int row_padding = 8;         // YUYV bytesperline = 2 × width + padding
  int unplug_after = -1;       // frames delivered before the device vanishes
  int stall_after = -1;        // frames delivered before the device stops sending
  int corrupt_frame = -1;      // this frame comes flagged V4L2_BUF_FLAG_ERROR
};

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
    if (Unplugged()) {
      fds[0].revents = POLLERR;
      return 1;
    }
    if (Stalled() || queue_.empty()) {
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
      case VIDIOC_S_FMT: {
        if (c_.sfmt_errno) return Error(c_.sfmt_errno);
        auto& pix = static_cast<v4l2_format*>(arg)->fmt.pix;
        format_ = pix.pixelformat;
        pix.width = static_cast<uint32_t>(c_.native.width);
        pix.height = static_cast<uint32_t>(c_.native.height);
        pix.bytesperline = format_ == V4L2_PIX_FMT_YUYV ? 2 * pix.width + c_.row_padding : 0;
        pix.sizeimage = format_ == V4L2_PIX_FMT_YUYV ? pix.bytesperline * pix.height : 65536;
        sizeimage_ = pix.sizeimage;
        return 0;
      }
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

  bool open() const { return open_; }
  bool streaming() const { return streaming_; }
  int mapped() const { return mapped_; }
  int streamoffs() const { return streamoffs_; }

 private:
  static constexpr int kFd = 42;
  static constexpr size_t kPage = 4096;
  static int Error(int err) {
    errno = err;
    return -1;
  }
  bool Unplugged() const { return c_.unplug_after >= 0 && produced_ >= c_.unplug_after; }
  bool Stalled() const { return c_.stall_after >= 0 && produced_ >= c_.stall_after; }

  int Dequeue(v4l2_buffer* b) {
    if (Unplugged()) return Error(ENODEV);
    if (!streaming_ || queue_.empty()) return Error(EAGAIN);
    const uint32_t index = queue_.front();
    queue_.pop_front();
    std::vector<uint8_t>& data = buffers_[index];
    const cv::Mat bgr = test::MakeImage(c_.native.width, c_.native.height, produced_);
    if (format_ == V4L2_PIX_FMT_YUYV) {
      const std::vector<uint8_t> packed = test::PackYuyv(bgr, c_.row_padding);
      EXPECT_EQ(packed.size(), data.size());
      std::copy(packed.begin(), packed.end(), data.begin());
      b->bytesused = static_cast<uint32_t>(data.size());
    } else {
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
      EXPECT_LE(jpeg.size(), data.size());
      std::copy(jpeg.begin(), jpeg.end(), data.begin());
      b->bytesused = static_cast<uint32_t>(jpeg.size());
    }
    b->index = index;
    b->sequence = static_cast<uint32_t>(produced_);
    b->timestamp.tv_sec = 100 + produced_ / 30;
    b->timestamp.tv_usec = (produced_ % 30) * 1000000 / 30;
    b->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | (produced_ == c_.corrupt_frame ? V4L2_BUF_FLAG_ERROR : 0);
    ++produced_;
    return 0;
  }

  FakeConfig c_;
  bool open_ = false, streaming_ = false;
  int mapped_ = 0, streamoffs_ = 0, produced_ = 0;
  uint32_t format_ = 0, sizeimage_ = 0;
  std::vector<std::vector<uint8_t>> buffers_;
  std::deque<uint32_t> queue_;
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
    EXPECT_TRUE(camera.streaming());
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

}  // namespace
}  // namespace arview::recordings
