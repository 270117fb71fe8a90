// A V4L2 camera for the `arview` binary, where no camera is attached: preloaded (LD_PRELOAD),
// it answers the system calls V4l2Source makes (stat, open, ioctl, mmap, poll, munmap, close)
// for the device kFakeDevice and passes every other call to the C library. The camera streams
// 64x48 YUYV frames of one grey (their PNGs are a few hundred bytes) at about 30 per second, with
// monotonic timestamps, until the reader stops. What `arview record` does with them is the
// real command's doing: tests/faults_test.cpp runs it on a full disk. (In-process tests stand in
// a camera through V4l2Io instead: recordings/v4l2_fake_camera_test.cpp.)

#include <dlfcn.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdarg>
#include <cstdint>
#include <cstring>
#include <deque>
#include <thread>
#include <vector>

namespace {

constexpr const char* kFakeDevice = "/dev/video-arview-fake";
constexpr uint32_t kWidth = 64, kHeight = 48;
constexpr size_t kFrameBytes = 2 * kWidth * kHeight;
constexpr size_t kPage = 4096;

// The C library's own functions, found once.
template <class Function>
Function Next(const char* name) {
  return reinterpret_cast<Function>(::dlsym(RTLD_NEXT, name));
}

struct Camera {
  int fd = -1;  // a real descriptor (of /dev/null), so that its number is never another file's
  bool streaming = false;
  uint32_t produced = 0;
  std::vector<std::vector<uint8_t>> buffers;
  std::deque<uint32_t> queued;
};

Camera& TheCamera() {
  static Camera camera;
  return camera;
}

bool IsFake(int fd) { return fd >= 0 && fd == TheCamera().fd; }

int Fail(int error) {
  errno = error;
  return -1;
}

int Dequeue(v4l2_buffer* b) {
  Camera& c = TheCamera();
  if (!c.streaming || c.queued.empty()) return Fail(EAGAIN);
  const uint32_t index = c.queued.front();
  c.queued.pop_front();
  std::memset(c.buffers[index].data(), 128, kFrameBytes);  // Y, U, V all mid-grey
  b->index = index;
  b->bytesused = static_cast<uint32_t>(kFrameBytes);
  b->sequence = c.produced;
  b->timestamp.tv_sec = 100 + c.produced / 30;
  b->timestamp.tv_usec = (c.produced % 30) * 1000000 / 30;
  b->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  ++c.produced;
  return 0;
}

int FakeIoctl(unsigned long request, void* arg) {
  Camera& c = TheCamera();
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      *cap = {};
      std::strcpy(reinterpret_cast<char*>(cap->card), "arview fake camera");
      cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
      cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto* d = static_cast<v4l2_fmtdesc*>(arg);
      if (d->index > 0) return Fail(EINVAL);
      d->pixelformat = V4L2_PIX_FMT_YUYV;
      return 0;
    }
    case VIDIOC_S_FMT: {
      auto& pix = static_cast<v4l2_format*>(arg)->fmt.pix;
      pix.pixelformat = V4L2_PIX_FMT_YUYV;
      pix.width = kWidth;
      pix.height = kHeight;
      pix.bytesperline = 2 * kWidth;
      pix.sizeimage = static_cast<uint32_t>(kFrameBytes);
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* req = static_cast<v4l2_requestbuffers*>(arg);
      req->count = req->count < 3 ? req->count : 3;
      c.buffers.assign(req->count, std::vector<uint8_t>(kFrameBytes));
      return 0;
    }
    case VIDIOC_QUERYBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= c.buffers.size()) return Fail(EINVAL);
      b->length = static_cast<uint32_t>(kFrameBytes);
      b->m.offset = static_cast<uint32_t>(b->index * kPage);
      return 0;
    }
    case VIDIOC_QBUF:
      c.queued.push_back(static_cast<v4l2_buffer*>(arg)->index);
      return 0;
    case VIDIOC_STREAMON:
      c.streaming = true;
      return 0;
    case VIDIOC_STREAMOFF:
      c.streaming = false;
      return 0;
    case VIDIOC_DQBUF:
      return Dequeue(static_cast<v4l2_buffer*>(arg));
  }
  return Fail(ENOTTY);
}

}  // namespace

extern "C" {

int stat(const char* path, struct stat* st) noexcept {
  if (std::strcmp(path, kFakeDevice) == 0) {
    *st = {};
    st->st_mode = S_IFCHR | 0660;
    return 0;
  }
  static const auto real = Next<int (*)(const char*, struct stat*)>("stat");
  return real(path, st);
}

int open(const char* path, int flags, ...) {
  mode_t mode = 0;
  if (flags & (O_CREAT | O_TMPFILE)) {
    va_list args;
    va_start(args, flags);
    mode = static_cast<mode_t>(va_arg(args, int));
    va_end(args);
  }
  static const auto real = Next<int (*)(const char*, int, ...)>("open");
  if (std::strcmp(path, kFakeDevice) == 0) {
    if (TheCamera().fd >= 0) return Fail(EBUSY);
    TheCamera() = Camera{};
    TheCamera().fd = real("/dev/null", O_RDWR | O_CLOEXEC);
    return TheCamera().fd;
  }
  return real(path, flags, mode);
}

int close(int fd) {
  static const auto real = Next<int (*)(int)>("close");
  if (IsFake(fd)) TheCamera().fd = -1;
  return real(fd);
}

int ioctl(int fd, unsigned long request, ...) noexcept {
  va_list args;
  va_start(args, request);
  void* arg = va_arg(args, void*);
  va_end(args);
  if (IsFake(fd)) return FakeIoctl(request, arg);
  static const auto real = Next<int (*)(int, unsigned long, ...)>("ioctl");
  return real(fd, request, arg);
}

// glibc 2.36 declares poll's array write-only (__attr_access), though poll reads its fd and
// events: gcc then thinks reading fds[0].fd reads uninitialised memory.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
int poll(pollfd* fds, nfds_t count, int timeout_ms) {
  if (count == 1 && IsFake(fds[0].fd)) {
    // About 30 frames a second, as a webcam.
    std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms < 33 ? timeout_ms : 33));
    fds[0].revents = TheCamera().queued.empty() ? 0 : POLLIN;
    return fds[0].revents ? 1 : 0;
  }
  static const auto real = Next<int (*)(pollfd*, nfds_t, int)>("poll");
  return real(fds, count, timeout_ms);
}
#pragma GCC diagnostic pop

void* mmap(void* address, size_t length, int protection, int flags, int fd, off_t offset) noexcept {
  if (IsFake(fd)) {
    const size_t index = static_cast<size_t>(offset) / kPage;
    if (index >= TheCamera().buffers.size() || length != kFrameBytes) return MAP_FAILED;
    return TheCamera().buffers[index].data();
  }
  static const auto real = Next<void* (*)(void*, size_t, int, int, int, off_t)>("mmap");
  return real(address, length, protection, flags, fd, offset);
}

int munmap(void* address, size_t length) noexcept {
  for (const auto& buffer : TheCamera().buffers) {
    if (address == buffer.data()) return 0;
  }
  static const auto real = Next<int (*)(void*, size_t)>("munmap");
  return real(address, length);
}

}  // extern "C"
