// An emulated V4L2 camera for the `arview` binary, where no camera is attached: preloaded
// (LD_PRELOAD), it answers the system calls V4l2Source makes (stat, open, ioctl, mmap, poll,
// munmap, close) for the device /dev/video-arview-fake, lists it in /dev on request (opendir,
// fdopendir, readdir, closedir) and passes every other call to the C library. What `arview
// record`, `run`, `camera list` and `camera info` do with it is the real commands' doing
// (tests/faults_test.cpp, tests/camera_test.cpp). In-process tests stand in a camera through
// V4l2Io instead: recordings/v4l2_fake_camera_test.cpp.
//
// What it emulates, as a USB 2 webcam with the uvcvideo driver does:
// - formats YUYV and MJPEG; sizes 640x480, 1280x720, 1920x1080 and the pictures' own size
//   (64x48 without a recording); frame sizes and intervals enumerable (ENUM_FRAMESIZES,
//   ENUM_FRAMEINTERVALS); S_FMT takes the nearest listed size, S_PARM the nearest listed rate
//   and G_PARM says which. YUYV is limited as USB 2 bandwidth limits it: 30 fps up to 640x480,
//   10 up to 1280x720, 5 above; MJPEG 30 at every size. Each lists the rates of 30, 15, 10 and 5
//   up to its highest. MJPEG frames are JPEGs of
//   quality 80 (cv::imencode), so their sizes are realistic.
// - controls (QUERYCTRL with V4L2_CTRL_FLAG_NEXT_CTRL, QUERYMENU, G_CTRL, S_CTRL): the camera
//   class heading, exposure_auto (menu: 1 manual, 3 aperture priority; starts at 3),
//   exposure_absolute (3..2047, 250), focus_absolute (0..250 step 5, 40), focus_auto (bool,
//   starts on). As uvcvideo, a position control is inactive while its automatic mode runs and
//   setting it then fails with EACCES; a value out of range fails with ERANGE.
// - driver-like buffers: from STREAMON a producer thread fills the next queued buffer at every
//   frame time on CLOCK_MONOTONIC (absolute deadlines: no drift); a frame that finds no queued
//   buffer is dropped and its sequence number skipped; frame times missed while the process was
//   stopped are caught up (free buffers filled, the rest dropped). Buffers carry their frame
//   time on CLOCK_MONOTONIC with V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC. poll() waits (a condition variable) for
//   a filled buffer within its timeout.
//
// Configured by environment variables, read at each open of the device:
//   ARVIEW_FAKE_CAMERA_RECORDING=<folder>   play this recording folder (frames.txt listing one
//       image per frame; camera.yaml beside it), looping, each picture resized to the granted
//       size. Without it: uniform grey frames (a 64x48 YUYV grey frame makes a 195-byte PNG).
//   ARVIEW_FAKE_CAMERA_UNPLUG_AFTER=<n>     after n frames the device is gone: DQBUF and QBUF
//       fail with ENODEV, poll() says POLLERR.
//   ARVIEW_FAKE_CAMERA_STALL_AFTER=<n>      after n frames nothing more is delivered.
//   ARVIEW_FAKE_CAMERA_CORRUPT_EVERY=<n>    every nth frame is corrupt: an MJPEG frame cut to
//       half its length (a USB hiccup), a YUYV frame flagged V4L2_BUF_FLAG_ERROR.
//   ARVIEW_FAKE_CAMERA_HALF_RATE_AFTER=<n>  after n frames the interval doubles (a camera whose
//       automatic exposure lengthens in dim light).
//   ARVIEW_FAKE_CAMERA_PRELOAD=1            STREAMON makes every picture's payload (on all cores,
//       up to the cache's 256 MB) before the sensor starts: nothing is decoded or encoded while
//       the camera streams, as with a real camera, whose encoder is its own chip. For latency
//       measurements at sizes where the emulation's encoding would take a large share of the
//       reader's cores (1280x720 and up); STREAMON then takes seconds.
//   ARVIEW_FAKE_CAMERA_NODE=/dev/videoN     the camera also answers at this path, and a listing
//       of its folder (opendir/readdir, as `arview camera list` reads /dev) shows it after the
//       real entries, as a plugged-in webcam's node. /dev/video-arview-fake is not listed: it
//       is not a name a driver gives (video<number>).
// "Frames" counts every frame time since STREAMON, dropped ones included. A value that is not
// a whole number, or a recording that cannot be read, makes open() fail with EINVAL after one
// line on stderr: a test set up wrongly must not pass on grey frames.

#include <dirent.h>
#include <dlfcn.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace {

constexpr const char* kFakeDevice = "/dev/video-arview-fake";
constexpr size_t kPage = 4096;
constexpr uint32_t kMaxBuffers = 32;
constexpr int kJpegQuality = 80;
// Encoded pictures are kept for the next lap up to this many bytes (a 1080p YUYV lap of 300
// frames would not fit; those are encoded again each time).
constexpr size_t kCacheBytes = 256u << 20;

// The C library's own function `name`, found at its first use and kept in `slot`: a
// constant-initialised atomic, where a function-local static with a dynamic initialiser would
// take a guard (__cxa_guard_acquire/release). ThreadSanitizer intercepts those guards, and its
// runtime's own start-up calls mmap before the runtime exists: a tsan build of arview with this
// library preloaded died with SEGV in TSan's guard_release before main (docs/reliability.md,
// "The live crash"). Two threads finding it at once store the same address.
template <class Function>
Function Real(std::atomic<void*>& slot, const char* name) {
  void* function = slot.load(std::memory_order_acquire);
  if (function == nullptr) {
    function = ::dlsym(RTLD_NEXT, name);
    slot.store(function, std::memory_order_release);
  }
  return reinterpret_cast<Function>(function);
}

// The listed node (ARVIEW_FAKE_CAMERA_NODE), "" when none.
std::string ListedNode() {
  const char* node = std::getenv("ARVIEW_FAKE_CAMERA_NODE");
  return node != nullptr ? node : "";
}

bool IsFakePath(const char* path) {
  if (path == nullptr) return false;
  if (std::strcmp(path, kFakeDevice) == 0) return true;
  const std::string node = ListedNode();
  return !node.empty() && node == path;
}

// ---- Settings ----

struct Settings {
  std::string recording;
  long unplug_after = -1, stall_after = -1, corrupt_every = 0, half_rate_after = -1;
  long preload = 0;  // 1: every payload made at STREAMON
};

bool ReadCount(const char* name, long& value) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return true;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (errno != 0 || *end != '\0' || v < 0) {
    std::fprintf(stderr, "arview fake camera: %s='%s' is not a whole number of frames\n", name, text);
    return false;
  }
  value = v;
  return true;
}

bool ReadSettings(Settings& s) {
  if (const char* r = std::getenv("ARVIEW_FAKE_CAMERA_RECORDING")) s.recording = r;
  return ReadCount("ARVIEW_FAKE_CAMERA_UNPLUG_AFTER", s.unplug_after) &&
         ReadCount("ARVIEW_FAKE_CAMERA_STALL_AFTER", s.stall_after) &&
         ReadCount("ARVIEW_FAKE_CAMERA_CORRUPT_EVERY", s.corrupt_every) &&
         ReadCount("ARVIEW_FAKE_CAMERA_HALF_RATE_AFTER", s.half_rate_after) &&
         ReadCount("ARVIEW_FAKE_CAMERA_PRELOAD", s.preload);
}

// The image files a recording's frames.txt lists ("timestamp relative/path"; '#' comments).
bool ReadFrameList(const std::string& folder, std::vector<std::string>& paths) {
  std::ifstream list(folder + "/frames.txt");
  if (!list) {
    std::fprintf(stderr, "arview fake camera: %s/frames.txt cannot be read\n", folder.c_str());
    return false;
  }
  std::string line;
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double timestamp = 0;
    std::string path;
    if (!(fields >> timestamp >> path)) continue;
    paths.push_back(folder + "/" + path);
  }
  if (paths.empty()) std::fprintf(stderr, "arview fake camera: %s/frames.txt lists no frames\n", folder.c_str());
  return !paths.empty();
}

// ---- Modes: formats, sizes, rates ----

bool IsFormat(uint32_t f) { return f == V4L2_PIX_FMT_YUYV || f == V4L2_PIX_FMT_MJPEG; }

// USB 2 carries about 24 MB/s of isochronous video: YUYV (2 bytes a pixel) reaches 30 fps only
// up to 640x480, 10 up to 1280x720. MJPEG is compressed in the camera: 30 fps at every size.
uint32_t MaxFps(uint32_t format, cv::Size size) {
  if (format == V4L2_PIX_FMT_MJPEG) return 30;
  const long pixels = long{size.width} * size.height;
  if (pixels <= 640L * 480) return 30;
  if (pixels <= 1280L * 720) return 10;
  return 5;
}

std::vector<uint32_t> Rates(uint32_t format, cv::Size size) {
  std::vector<uint32_t> rates;
  for (uint32_t fps : {30u, 15u, 10u, 5u}) {
    if (fps <= MaxFps(format, size)) rates.push_back(fps);
  }
  return rates;
}

// ---- YUYV packing (BT.601 limited range, as cameras send and cv::COLOR_YUV2BGR_YUYV reads) ----

void PackYuyv(const cv::Mat& bgr, uint8_t* out) {
  for (int y = 0; y < bgr.rows; ++y) {
    const auto* row = bgr.ptr<cv::Vec3b>(y);
    uint8_t* o = out + static_cast<size_t>(y) * 2 * bgr.cols;
    for (int x = 0; x + 1 < bgr.cols; x += 2) {
      int u = 0, v = 0;
      for (int k = 0; k < 2; ++k) {
        const int b = row[x + k][0], g = row[x + k][1], r = row[x + k][2];
        o[2 * (x + k)] = static_cast<uint8_t>(std::clamp((66 * r + 129 * g + 25 * b + 128) / 256 + 16, 0, 255));
        u += (-38 * r - 74 * g + 112 * b + 128) / 256 + 128;
        v += (112 * r - 94 * g - 18 * b + 128) / 256 + 128;
      }
      o[2 * x + 1] = static_cast<uint8_t>(std::clamp(u / 2, 0, 255));
      o[2 * x + 3] = static_cast<uint8_t>(std::clamp(v / 2, 0, 255));
    }
  }
}

// ---- The camera ----

struct Control {
  v4l2_queryctrl query{};
  int32_t value = 0;
  std::vector<uint32_t> menu;  // the menu indices it names
};

Control MakeControl(uint32_t id, const char* name, uint32_t type, int32_t min, int32_t max, int32_t step,
                    int32_t value, std::vector<uint32_t> menu = {}) {
  Control c;
  c.query.id = id;
  std::snprintf(reinterpret_cast<char*>(c.query.name), sizeof(c.query.name), "%s", name);
  c.query.type = type;
  c.query.minimum = min;
  c.query.maximum = max;
  c.query.step = step;
  c.query.default_value = value;
  c.value = value;
  c.menu = std::move(menu);
  return c;
}

class Camera {
 public:
  Camera(Settings settings, std::vector<std::string> pictures, cv::Size native)
      : settings_(std::move(settings)), pictures_(std::move(pictures)), native_(native) {
    for (const cv::Size s : {native_, cv::Size(640, 480), cv::Size(1280, 720), cv::Size(1920, 1080)}) {
      if (std::find(sizes_.begin(), sizes_.end(), s) == sizes_.end()) sizes_.push_back(s);
    }
    std::sort(sizes_.begin(), sizes_.end(), [](cv::Size a, cv::Size b) { return a.area() < b.area(); });
    size_ = native_;
    interval_ = {1, MaxFps(format_, size_)};
    controls_ = {MakeControl(V4L2_CID_CAMERA_CLASS, "Camera Controls", V4L2_CTRL_TYPE_CTRL_CLASS, 0, 0, 0, 0),
                 MakeControl(V4L2_CID_EXPOSURE_AUTO, "Auto Exposure", V4L2_CTRL_TYPE_MENU, 0, 3, 1, 3, {1, 3}),
                 MakeControl(V4L2_CID_EXPOSURE_ABSOLUTE, "Exposure Time, Absolute", V4L2_CTRL_TYPE_INTEGER, 3, 2047, 1, 250),
                 MakeControl(V4L2_CID_FOCUS_ABSOLUTE, "Focus, Absolute", V4L2_CTRL_TYPE_INTEGER, 0, 250, 5, 40),
                 MakeControl(V4L2_CID_FOCUS_AUTO, "Focus, Automatic Continuous", V4L2_CTRL_TYPE_BOOLEAN, 0, 1, 1, 1)};
  }
  ~Camera() { StopProducer(); }

  int Ioctl(unsigned long request, void* arg);
  int Poll(pollfd& p, int timeout_ms);
  void* Map(size_t length, off_t offset);
  void Close() { StopProducer(); }
  // Whether `address` is one of the buffers (munmap of it is the camera's to answer).
  bool Owns(const void* address) const {
    for (const auto& a : mapped_) {
      if (a.load() == address) return true;
    }
    return false;
  }

 private:
  static int Fail(int error) {
    errno = error;
    return -1;
  }
  uint32_t FrameBytes() const {
    const uint32_t yuyv = 2u * static_cast<uint32_t>(size_.width) * static_cast<uint32_t>(size_.height);
    return format_ == V4L2_PIX_FMT_YUYV ? yuyv : std::max<uint32_t>(yuyv, 65536);
  }
  int EnumFormat(v4l2_fmtdesc* d) const;
  int EnumSizes(v4l2_frmsizeenum* fs) const;
  int EnumIntervals(v4l2_frmivalenum* fi) const;
  void FillFormat(v4l2_pix_format& pix) const;
  int SetFormat(v4l2_pix_format& pix, bool try_only);
  int Parm(unsigned long request, v4l2_streamparm* p);
  Control* FindControl(uint32_t id);
  bool Inactive(uint32_t id);
  int QueryControl(v4l2_queryctrl* q);
  int QueryMenu(v4l2_querymenu* m);
  int SetControl(v4l2_control* v);
  int RequestBuffers(v4l2_requestbuffers* req);
  int StreamOn();
  int StreamOff();
  int Dequeue(v4l2_buffer* b);

  void StartProducer();
  void StopProducer();
  void Produce();
  const std::vector<uint8_t>& Payload(long n);
  std::vector<uint8_t> MakePayload(size_t index) const;
  bool Cache(size_t index, std::vector<uint8_t>& payload);
  void Preload();

  Settings settings_;
  std::vector<std::string> pictures_;  // empty: grey frames
  cv::Size native_;
  std::vector<cv::Size> sizes_;

  std::mutex m_;
  std::condition_variable changed_;  // a buffer filled, the device gone, streaming stopped
  uint32_t format_ = V4L2_PIX_FMT_YUYV;
  cv::Size size_;
  v4l2_fract interval_{1, 30};
  std::vector<Control> controls_;
  std::vector<std::vector<uint8_t>> buffers_;
  std::array<std::atomic<const void*>, kMaxBuffers> mapped_{};
  std::deque<uint32_t> queued_;
  std::deque<v4l2_buffer> filled_;
  bool streaming_ = false, stop_ = false, unplugged_ = false;
  long sequence_ = 0;  // frame times since STREAMON, dropped frames included

  // The producer's own (no lock): encoded pictures for the format and size streamed.
  std::thread producer_;
  std::vector<std::vector<uint8_t>> cache_;
  size_t cache_bytes_ = 0;
  std::vector<uint8_t> scratch_;
};

int Camera::EnumFormat(v4l2_fmtdesc* d) const {
  if (d->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || d->index > 1) return Fail(EINVAL);
  const bool mjpeg = d->index == 1;
  const uint32_t index = d->index;
  *d = {};
  d->index = index;
  d->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  d->pixelformat = mjpeg ? V4L2_PIX_FMT_MJPEG : V4L2_PIX_FMT_YUYV;
  d->flags = mjpeg ? V4L2_FMT_FLAG_COMPRESSED : 0;
  std::snprintf(reinterpret_cast<char*>(d->description), sizeof(d->description), "%s",
                mjpeg ? "Motion-JPEG" : "YUYV 4:2:2");
  return 0;
}

int Camera::EnumSizes(v4l2_frmsizeenum* fs) const {
  if (!IsFormat(fs->pixel_format) || fs->index >= sizes_.size()) return Fail(EINVAL);
  fs->type = V4L2_FRMSIZE_TYPE_DISCRETE;
  fs->discrete.width = static_cast<uint32_t>(sizes_[fs->index].width);
  fs->discrete.height = static_cast<uint32_t>(sizes_[fs->index].height);
  return 0;
}

int Camera::EnumIntervals(v4l2_frmivalenum* fi) const {
  const cv::Size size(static_cast<int>(fi->width), static_cast<int>(fi->height));
  if (!IsFormat(fi->pixel_format) || std::find(sizes_.begin(), sizes_.end(), size) == sizes_.end()) return Fail(EINVAL);
  const std::vector<uint32_t> rates = Rates(fi->pixel_format, size);
  if (fi->index >= rates.size()) return Fail(EINVAL);
  fi->type = V4L2_FRMIVAL_TYPE_DISCRETE;
  fi->discrete = {1, rates[fi->index]};
  return 0;
}

void Camera::FillFormat(v4l2_pix_format& pix) const {
  pix = {};
  pix.width = static_cast<uint32_t>(size_.width);
  pix.height = static_cast<uint32_t>(size_.height);
  pix.pixelformat = format_;
  pix.field = V4L2_FIELD_NONE;
  pix.bytesperline = format_ == V4L2_PIX_FMT_YUYV ? 2 * pix.width : 0;
  pix.sizeimage = FrameBytes();
  pix.colorspace = format_ == V4L2_PIX_FMT_YUYV ? V4L2_COLORSPACE_SRGB : V4L2_COLORSPACE_JPEG;
}

int Camera::SetFormat(v4l2_pix_format& pix, bool try_only) {
  if (!try_only && (streaming_ || !buffers_.empty())) return Fail(EBUSY);
  const uint32_t format = IsFormat(pix.pixelformat) ? pix.pixelformat : V4L2_PIX_FMT_YUYV;
  cv::Size best = sizes_.front();
  long best_distance = -1;
  for (const cv::Size s : sizes_) {  // the nearest listed size, as uvcvideo picks
    const long d = std::labs(long{s.width} - long{pix.width}) + std::labs(long{s.height} - long{pix.height});
    if (best_distance < 0 || d < best_distance) {
      best_distance = d;
      best = s;
    }
  }
  const uint32_t old_format = format_;
  const cv::Size old_size = size_;
  format_ = format;
  size_ = best;
  FillFormat(pix);
  if (try_only) {
    format_ = old_format;
    size_ = old_size;
  } else {
    interval_ = {1, MaxFps(format_, size_)};  // a new format starts at its highest rate
  }
  return 0;
}

int Camera::Parm(unsigned long request, v4l2_streamparm* p) {
  if (p->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
  if (request == VIDIOC_S_PARM) {
    if (streaming_) return Fail(EBUSY);
    const v4l2_fract asked = p->parm.capture.timeperframe;
    const double fps = asked.numerator ? double(asked.denominator) / asked.numerator : 1e9;
    uint32_t best = 0;
    for (uint32_t r : Rates(format_, size_)) {  // the listed rate nearest to the one asked
      if (best == 0 || std::abs(r - fps) < std::abs(best - fps)) best = r;
    }
    interval_ = {1, best};
  }
  p->parm.capture = {};
  p->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
  p->parm.capture.timeperframe = interval_;
  return 0;
}

Control* Camera::FindControl(uint32_t id) {
  for (Control& c : controls_) {
    if (c.query.id == id) return &c;
  }
  return nullptr;
}

// A position control while its automatic mode runs, as uvcvideo marks them.
bool Camera::Inactive(uint32_t id) {
  if (id == V4L2_CID_FOCUS_ABSOLUTE) return FindControl(V4L2_CID_FOCUS_AUTO)->value == 1;
  if (id == V4L2_CID_EXPOSURE_ABSOLUTE) return FindControl(V4L2_CID_EXPOSURE_AUTO)->value != V4L2_EXPOSURE_MANUAL;
  return false;
}

int Camera::QueryControl(v4l2_queryctrl* q) {
  const bool next = (q->id & V4L2_CTRL_FLAG_NEXT_CTRL) != 0;
  const uint32_t id = q->id & ~(V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND);
  for (const Control& c : controls_) {  // in id order
    if (next ? c.query.id > id : c.query.id == id) {
      *q = c.query;
      if (Inactive(c.query.id)) q->flags |= V4L2_CTRL_FLAG_INACTIVE;
      return 0;
    }
  }
  return Fail(EINVAL);
}

int Camera::QueryMenu(v4l2_querymenu* m) {
  const Control* c = FindControl(m->id);
  if (c == nullptr || std::find(c->menu.begin(), c->menu.end(), m->index) == c->menu.end()) return Fail(EINVAL);
  std::snprintf(reinterpret_cast<char*>(m->name), sizeof(m->name), "%s",
                m->index == V4L2_EXPOSURE_MANUAL ? "Manual Mode" : "Aperture Priority Mode");
  return 0;
}

int Camera::SetControl(v4l2_control* v) {
  Control* c = FindControl(v->id);
  if (c == nullptr || c->query.type == V4L2_CTRL_TYPE_CTRL_CLASS) return Fail(EINVAL);
  if (v->value < c->query.minimum || v->value > c->query.maximum) return Fail(ERANGE);
  if (!c->menu.empty() && std::find(c->menu.begin(), c->menu.end(), static_cast<uint32_t>(v->value)) == c->menu.end()) {
    return Fail(EINVAL);
  }
  if (Inactive(v->id)) return Fail(EACCES);
  c->value = v->value;
  return 0;
}

int Camera::RequestBuffers(v4l2_requestbuffers* req) {
  if (req->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || req->memory != V4L2_MEMORY_MMAP) return Fail(EINVAL);
  if (streaming_) return Fail(EBUSY);
  const uint32_t count = std::min(req->count, kMaxBuffers);
  for (auto& a : mapped_) a.store(nullptr);
  buffers_.assign(count, std::vector<uint8_t>(FrameBytes()));
  for (uint32_t i = 0; i < count; ++i) mapped_[i].store(buffers_[i].data());
  queued_.clear();
  filled_.clear();
  req->count = count;
  return 0;
}

int Camera::StreamOn() {
  if (unplugged_) return Fail(ENODEV);
  if (buffers_.empty()) return Fail(EINVAL);
  if (streaming_) return 0;
  streaming_ = true;
  stop_ = false;
  sequence_ = 0;
  StartProducer();
  return 0;
}

int Camera::StreamOff() {
  streaming_ = false;
  stop_ = true;
  queued_.clear();
  filled_.clear();
  changed_.notify_all();
  return unplugged_ ? Fail(ENODEV) : 0;
}

int Camera::Dequeue(v4l2_buffer* b) {
  if (unplugged_) return Fail(ENODEV);
  if (!streaming_) return Fail(EINVAL);
  if (filled_.empty()) return Fail(EAGAIN);
  *b = filled_.front();
  filled_.pop_front();
  return 0;
}

int Camera::Ioctl(unsigned long request, void* arg) {
  bool stop_producer = false;
  int result = 0;
  {
    std::lock_guard<std::mutex> lock(m_);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        *cap = {};
        std::snprintf(reinterpret_cast<char*>(cap->driver), sizeof(cap->driver), "uvcvideo");
        std::snprintf(reinterpret_cast<char*>(cap->card), sizeof(cap->card), "arview emulated camera");
        std::snprintf(reinterpret_cast<char*>(cap->bus_info), sizeof(cap->bus_info), "usb-arview-fake");
        cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
        return 0;
      }
      case VIDIOC_ENUM_FMT: return EnumFormat(static_cast<v4l2_fmtdesc*>(arg));
      case VIDIOC_ENUM_FRAMESIZES: return EnumSizes(static_cast<v4l2_frmsizeenum*>(arg));
      case VIDIOC_ENUM_FRAMEINTERVALS: return EnumIntervals(static_cast<v4l2_frmivalenum*>(arg));
      case VIDIOC_G_FMT: FillFormat(static_cast<v4l2_format*>(arg)->fmt.pix); return 0;
      case VIDIOC_S_FMT: return SetFormat(static_cast<v4l2_format*>(arg)->fmt.pix, false);
      case VIDIOC_TRY_FMT: return SetFormat(static_cast<v4l2_format*>(arg)->fmt.pix, true);
      case VIDIOC_G_PARM:
      case VIDIOC_S_PARM: return Parm(request, static_cast<v4l2_streamparm*>(arg));
      case VIDIOC_QUERYCTRL: return QueryControl(static_cast<v4l2_queryctrl*>(arg));
      case VIDIOC_QUERYMENU: return QueryMenu(static_cast<v4l2_querymenu*>(arg));
      case VIDIOC_G_CTRL: {
        auto* v = static_cast<v4l2_control*>(arg);
        const Control* c = FindControl(v->id);
        if (c == nullptr || c->query.type == V4L2_CTRL_TYPE_CTRL_CLASS) return Fail(EINVAL);
        v->value = c->value;
        return 0;
      }
      case VIDIOC_S_CTRL: return SetControl(static_cast<v4l2_control*>(arg));
      case VIDIOC_REQBUFS: return RequestBuffers(static_cast<v4l2_requestbuffers*>(arg));
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return Fail(EINVAL);
        b->length = static_cast<uint32_t>(buffers_[b->index].size());
        b->m.offset = static_cast<uint32_t>(b->index * kPage);
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (unplugged_) return Fail(ENODEV);
        if (b->index >= buffers_.size()) return Fail(EINVAL);
        queued_.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF: return Dequeue(static_cast<v4l2_buffer*>(arg));
      case VIDIOC_STREAMON: return StreamOn();
      case VIDIOC_STREAMOFF:
        result = StreamOff();
        stop_producer = true;
        break;
      default: return Fail(ENOTTY);
    }
  }
  const int saved = errno;
  if (stop_producer) StopProducer();  // joined outside the lock the producer takes
  errno = saved;
  return result;
}

int Camera::Poll(pollfd& p, int timeout_ms) {
  std::unique_lock<std::mutex> lock(m_);
  auto ready = [&] { return unplugged_ || !streaming_ || !filled_.empty(); };
  if (timeout_ms < 0) {
    changed_.wait(lock, ready);
  } else {
    changed_.wait_for(lock, std::chrono::milliseconds(timeout_ms), ready);
  }
  if (unplugged_ || !streaming_) {
    p.revents = POLLERR;  // as videobuf2: an unplugged or stopped queue
    return 1;
  }
  p.revents = filled_.empty() ? 0 : static_cast<short>(p.events & (POLLIN | POLLRDNORM));
  return p.revents ? 1 : 0;
}

void* Camera::Map(size_t length, off_t offset) {
  std::lock_guard<std::mutex> lock(m_);
  const size_t index = static_cast<size_t>(offset) / kPage;
  if (index >= buffers_.size() || length != buffers_[index].size()) return MAP_FAILED;
  return buffers_[index].data();
}

void Camera::StartProducer() {
  // The cache holds pictures for one format and size: streaming starts after S_FMT settled them.
  cache_.assign(pictures_.empty() ? 1 : pictures_.size(), {});
  cache_bytes_ = 0;
  if (settings_.preload != 0) Preload();
  producer_ = std::thread([this] { Produce(); });
}

void Camera::StopProducer() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  changed_.notify_all();
  if (producer_.joinable()) producer_.join();
}

// Every picture's payload into the cache, in playing order, 16 at a time on all cores, until
// the cache is full. The batch's threads are this library's own, joined before the payloads are
// read: with cv::parallel_for_, TBB's workers handed them over by synchronization that TSan does
// not see (libtbb is not instrumented), and the producer's copy was reported as a race.
void Camera::Preload() {
  constexpr size_t kBatch = 16;
  const size_t threads = std::max(1u, std::thread::hardware_concurrency());
  for (size_t first = 0; first < cache_.size(); first += kBatch) {
    std::vector<std::vector<uint8_t>> made(std::min(kBatch, cache_.size() - first));
    std::atomic<size_t> next{0};
    {
      std::vector<std::jthread> makers;
      for (size_t t = 0; t < std::min(threads, made.size()); ++t) {
        makers.emplace_back([&] {
          for (size_t i = next++; i < made.size(); i = next++) made[i] = MakePayload(first + i);
        });
      }
    }  // joined
    for (size_t i = 0; i < made.size(); ++i) {
      if (!Cache(first + i, made[i])) return;
    }
  }
}

// Keeps picture `index`'s payload (moved from) for the next lap when the cache has room for it.
bool Camera::Cache(size_t index, std::vector<uint8_t>& payload) {
  if (cache_bytes_ + payload.size() > kCacheBytes) return false;
  cache_bytes_ += payload.size();
  cache_[index] = std::move(payload);
  return true;
}

// The picture of frame n at the streamed format and size, encoded as the camera sends it.
const std::vector<uint8_t>& Camera::Payload(long n) {
  const size_t index = pictures_.empty() ? 0 : static_cast<size_t>(n) % pictures_.size();
  if (!cache_[index].empty()) return cache_[index];
  std::vector<uint8_t> out = MakePayload(index);
  if (Cache(index, out)) return cache_[index];
  scratch_ = std::move(out);
  return scratch_;
}

std::vector<uint8_t> Camera::MakePayload(size_t index) const {
  cv::Mat bgr;
  if (pictures_.empty()) {
    bgr = cv::Mat(size_, CV_8UC3, cv::Scalar(128, 128, 128));
  } else {
    const cv::Mat picture = cv::imread(pictures_[index], cv::IMREAD_COLOR);
    bgr = picture.empty() ? cv::Mat(size_, CV_8UC3, cv::Scalar(0, 0, 255)) : picture;  // red: unreadable
    if (bgr.size() != size_) cv::resize(bgr, bgr, size_, 0, 0, cv::INTER_AREA);
  }
  std::vector<uint8_t> out;
  if (format_ == V4L2_PIX_FMT_YUYV) {
    out.resize(2 * static_cast<size_t>(size_.area()));
    if (pictures_.empty()) {
      std::fill(out.begin(), out.end(), 128);  // Y, U, V all mid-grey
    } else {
      PackYuyv(bgr, out.data());
    }
  } else {
    cv::imencode(".jpg", bgr, out, {cv::IMWRITE_JPEG_QUALITY, kJpegQuality});
  }
  return out;
}

// A time on steady_clock (CLOCK_MONOTONIC in libstdc++) as a buffer's timestamp.
timeval MonotonicTime(std::chrono::steady_clock::time_point t) {
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
  return {static_cast<time_t>(us / 1000000), static_cast<suseconds_t>(us % 1000000)};
}

// The sensor: one frame per interval on CLOCK_MONOTONIC (steady_clock), into the next queued
// buffer or dropped. Each frame's payload is made before its frame time, as a camera's encoder
// works during the exposure and read-out: the emulation's own decoding and JPEG encoding (on
// the reader's cores, where a real camera has its own chip) is not part of the frame's latency
// from its capture timestamp. The USB transfer is not emulated: the buffer is filled at the
// frame time. On a machine too busy to make a payload within a frame interval (a 1280x720 PNG
// decoded and encoded while other jobs run) the emulated sensor runs late and every latency
// includes that lag: `--stats`' `arrival` stage (capture to dequeue) shows it. Frame times
// missed (the process stopped, a slow encode) are caught up at once, as a sensor that went on
// meanwhile: the free buffers are filled, the rest dropped. (The emulation lives in the
// reader's process, so a SIGSTOP stops it too.)
void Camera::Produce() {
  using Clock = std::chrono::steady_clock;
  std::unique_lock<std::mutex> lock(m_);
  auto due = Clock::now();
  for (;;) {
    const long n = sequence_;
    const bool half = settings_.half_rate_after >= 0 && n >= settings_.half_rate_after;
    due += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
        (half ? 2.0 : 1.0) * interval_.numerator / std::max<uint32_t>(interval_.denominator, 1)));
    // Made without the lock: the reader goes on dequeueing meanwhile.
    lock.unlock();
    const std::vector<uint8_t>& payload = Payload(n);
    lock.lock();
    if (changed_.wait_until(lock, due, [&] { return stop_; })) return;
    if (settings_.unplug_after >= 0 && n >= settings_.unplug_after) {
      unplugged_ = true;
      changed_.notify_all();
      return;
    }
    if (settings_.stall_after >= 0 && n >= settings_.stall_after) {
      changed_.wait(lock, [&] { return stop_; });
      return;
    }
    ++sequence_;
    if (queued_.empty()) continue;  // no buffer: this frame is dropped, its number skipped
    const uint32_t index = queued_.front();
    queued_.pop_front();
    std::vector<uint8_t>& buffer = buffers_[index];
    const bool corrupt = settings_.corrupt_every > 0 && (n + 1) % settings_.corrupt_every == 0;
    size_t used = std::min(payload.size(), buffer.size());
    if (corrupt && format_ == V4L2_PIX_FMT_MJPEG) used /= 2;  // cut short, as by a USB hiccup
    std::memcpy(buffer.data(), payload.data(), used);
    v4l2_buffer b{};
    b.index = index;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.bytesused = static_cast<uint32_t>(used);
    b.field = V4L2_FIELD_NONE;
    b.sequence = static_cast<uint32_t>(n);
    b.timestamp = MonotonicTime(due);  // the frame's capture time, not when it was copied
    b.flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE | V4L2_BUF_FLAG_DONE;
    if (corrupt && format_ == V4L2_PIX_FMT_YUYV) b.flags |= V4L2_BUF_FLAG_ERROR;
    b.length = static_cast<uint32_t>(buffer.size());
    b.m.offset = static_cast<uint32_t>(index * kPage);
    filled_.push_back(b);
    changed_.notify_all();
  }
}

// ---- The device node ----

std::atomic<int> g_fd{-1};  // the fake camera's descriptor (one of /dev/null), -1 when closed
// Replaced at each open. The camera before is never deleted: munmap (any thread, any time)
// may be asking it whether an address is its own, and a reader may unmap its buffers after
// closing. A test process opens the device a few times.
std::atomic<Camera*> g_camera{nullptr};
std::mutex g_open;

bool IsFake(int fd) { return fd >= 0 && fd == g_fd.load(); }

int Fail(int error) {
  errno = error;
  return -1;
}

// Reads the settings and the recording; nullptr (after one line on stderr) when they are wrong.
std::unique_ptr<Camera> MakeCamera() {
  Settings settings;
  if (!ReadSettings(settings)) return nullptr;
  std::vector<std::string> pictures;
  cv::Size native(64, 48);
  if (!settings.recording.empty()) {
    if (!ReadFrameList(settings.recording, pictures)) return nullptr;
    const cv::Mat first = cv::imread(pictures.front(), cv::IMREAD_COLOR);
    if (first.empty()) {
      std::fprintf(stderr, "arview fake camera: %s cannot be read as an image\n", pictures.front().c_str());
      return nullptr;
    }
    native = first.size();
    if (native.width % 2 != 0) --native.width;  // YUYV packs pixel pairs
  }
  return std::make_unique<Camera>(std::move(settings), std::move(pictures), native);
}

// ---- The listed node in its folder's listing ----

// A folder being read whose listing gains the node: its entry, given once after the real ones.
struct Listing {
  bool given = false;
  dirent entry{};
  dirent64 entry64{};
};
std::mutex g_listings_mutex;
// Never destroyed: a folder may be read while the process exits.
std::map<DIR*, Listing>& Listings() {
  static auto* listings = new std::map<DIR*, Listing>;
  return *listings;
}

std::string WithoutTrailingSlashes(std::string path) {
  while (path.size() > 1 && path.back() == '/') path.pop_back();
  return path;
}

// Starts watching `dir` when `folder` is the listed node's folder.
void WatchIfNodesFolder(DIR* dir, const std::string& folder) {
  const std::string node = ListedNode();
  if (dir == nullptr || node.empty()) return;
  const size_t slash = node.rfind('/');
  if (slash == std::string::npos || slash + 1 >= node.size() || node.size() - slash > sizeof(dirent::d_name)) return;
  if (WithoutTrailingSlashes(folder) != WithoutTrailingSlashes(node.substr(0, std::max<size_t>(slash, 1)))) return;
  Listing listing;
  const std::string name = node.substr(slash + 1);
  std::memcpy(listing.entry.d_name, name.c_str(), name.size() + 1);
  std::memcpy(listing.entry64.d_name, name.c_str(), name.size() + 1);
  listing.entry.d_type = listing.entry64.d_type = DT_CHR;
  listing.entry.d_reclen = sizeof(dirent);
  listing.entry64.d_reclen = sizeof(dirent64);
  std::lock_guard<std::mutex> lock(g_listings_mutex);
  Listings()[dir] = listing;
}

// The node's entry when `dir` is watched and its real entries are done (`real_entry` null).
template <class Entry>
Entry* NodeEntryAfter(DIR* dir, Entry* real_entry, Entry Listing::*entry) {
  if (real_entry != nullptr) return real_entry;
  std::lock_guard<std::mutex> lock(g_listings_mutex);
  const auto it = Listings().find(dir);
  if (it == Listings().end() || it->second.given) return nullptr;
  it->second.given = true;
  return &(it->second.*entry);
}

}  // namespace

extern "C" {

DIR* opendir(const char* name) {
  static std::atomic<void*> real_slot;
  const auto real = Real<DIR* (*)(const char*)>(real_slot, "opendir");
  DIR* dir = real(name);
  WatchIfNodesFolder(dir, name);
  return dir;
}

// libstdc++'s directory_iterator opens with openat and reads through fdopendir.
DIR* fdopendir(int fd) {
  static std::atomic<void*> real_slot;
  const auto real = Real<DIR* (*)(int)>(real_slot, "fdopendir");
  DIR* dir = real(fd);
  if (dir != nullptr && !ListedNode().empty()) {
    char target[4096];
    const std::string link = "/proc/self/fd/" + std::to_string(fd);
    const ssize_t length = ::readlink(link.c_str(), target, sizeof(target) - 1);
    if (length > 0) WatchIfNodesFolder(dir, std::string(target, static_cast<size_t>(length)));
  }
  return dir;
}

dirent* readdir(DIR* dir) {
  static std::atomic<void*> real_slot;
  const auto real = Real<dirent* (*)(DIR*)>(real_slot, "readdir");
  return NodeEntryAfter(dir, real(dir), &Listing::entry);
}

dirent64* readdir64(DIR* dir) {
  static std::atomic<void*> real_slot;
  const auto real = Real<dirent64* (*)(DIR*)>(real_slot, "readdir64");
  return NodeEntryAfter(dir, real(dir), &Listing::entry64);
}

int closedir(DIR* dir) {
  {
    std::lock_guard<std::mutex> lock(g_listings_mutex);
    Listings().erase(dir);
  }
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(DIR*)>(real_slot, "closedir");
  return real(dir);
}

int stat(const char* path, struct stat* st) noexcept {
  if (IsFakePath(path)) {
    *st = {};
    st->st_mode = S_IFCHR | 0660;
    return 0;
  }
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(const char*, struct stat*)>(real_slot, "stat");
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
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(const char*, int, ...)>(real_slot, "open");
  if (!IsFakePath(path)) return real(path, flags, mode);
  std::lock_guard<std::mutex> lock(g_open);
  if (g_fd.load() >= 0) return Fail(EBUSY);
  std::unique_ptr<Camera> camera = MakeCamera();
  if (!camera) return Fail(EINVAL);
  g_camera.store(camera.release());
  const int fd = real("/dev/null", O_RDWR | O_CLOEXEC);
  g_fd.store(fd);
  return fd;
}

int close(int fd) {
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(int)>(real_slot, "close");
  if (IsFake(fd)) {
    std::lock_guard<std::mutex> lock(g_open);
    g_camera.load()->Close();
    g_fd.store(-1);
  }
  return real(fd);
}

int ioctl(int fd, unsigned long request, ...) noexcept {
  va_list args;
  va_start(args, request);
  void* arg = va_arg(args, void*);
  va_end(args);
  if (IsFake(fd)) return g_camera.load()->Ioctl(request, arg);
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(int, unsigned long, ...)>(real_slot, "ioctl");
  return real(fd, request, arg);
}

// glibc 2.36 declares poll's array write-only (__attr_access), though poll reads its fd and
// events: gcc then thinks reading fds[0].fd reads uninitialised memory.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
int poll(pollfd* fds, nfds_t count, int timeout_ms) {
  if (count == 1 && IsFake(fds[0].fd)) return g_camera.load()->Poll(fds[0], timeout_ms);
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(pollfd*, nfds_t, int)>(real_slot, "poll");
  return real(fds, count, timeout_ms);
}
#pragma GCC diagnostic pop

void* mmap(void* address, size_t length, int protection, int flags, int fd, off_t offset) noexcept {
  if (IsFake(fd)) return g_camera.load()->Map(length, offset);
  static std::atomic<void*> real_slot;
  const auto real = Real<void* (*)(void*, size_t, int, int, int, off_t)>(real_slot, "mmap");
  return real(address, length, protection, flags, fd, offset);
}

// Called for every munmap in the process (the allocator's too): no lock, only the atomics of
// the buffer addresses.
int munmap(void* address, size_t length) noexcept {
  if (Camera* camera = g_camera.load(); camera != nullptr && camera->Owns(address)) return 0;
  static std::atomic<void*> real_slot;
  const auto real = Real<int (*)(void*, size_t)>(real_slot, "munmap");
  return real(address, length);
}

}  // extern "C"
