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

std::string ErrnoText(int err) { return std::strerror(err); }

[[noreturn]] void DeviceFail(const std::string& device, const std::string& problem) {
  throw SourceError(device + ": " + problem);
}

int RetryIoctl(V4l2Io& io, int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = io.Ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

// "30", "7.5", "29.97": a rate as a person writes it.
std::string FpsText(double fps) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", fps);
  return text;
}

std::string SizeText(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

double IntervalFps(const v4l2_fract& interval) {
  return interval.numerator > 0 ? static_cast<double>(interval.denominator) / interval.numerator : 0.0;
}

// The stat and open checks with one message per way they fail.
int OpenDevice(V4l2Io& io, const std::string& device) {
  struct stat st {};
  if (io.Stat(device.c_str(), &st) != 0) {
    if (errno == ENOENT) DeviceFail(device, "no such device (is the camera plugged in? see 'arview camera list')");
    DeviceFail(device, "cannot be inspected (" + ErrnoText(errno) + ")");
  }
  if (!S_ISCHR(st.st_mode)) DeviceFail(device, "not a video device (not a character device)");
  const int fd = io.Open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    if (err == EACCES) DeviceFail(device, "permission denied (add the user to the 'video' group)");
    if (err == EBUSY) DeviceFail(device, "busy (another program is using the camera)");
    if (err == ENODEV || err == ENXIO) DeviceFail(device, "no such device (unplugged?)");
    DeviceFail(device, "cannot be opened (" + ErrnoText(err) + ")");
  }
  return fd;
}

struct DeviceIdentity {
  std::string card, driver, bus;
  uint32_t caps = 0;  // the node's own capabilities
};

DeviceIdentity QueryIdentity(V4l2Io& io, int fd, const std::string& device) {
  v4l2_capability cap{};
  if (RetryIoctl(io, fd, VIDIOC_QUERYCAP, &cap) != 0) {
    if (errno == ENOTTY || errno == EINVAL) DeviceFail(device, "not a V4L2 video device");
    if (errno == ENODEV) DeviceFail(device, "no such device (unplugged?)");
    DeviceFail(device, "capability query failed (" + ErrnoText(errno) + ")");
  }
  // The driver's strings are fixed arrays, NUL-terminated by the API; bounded all the same.
  auto text = [](const uint8_t* s, size_t n) {
    return std::string(reinterpret_cast<const char*>(s), strnlen(reinterpret_cast<const char*>(s), n));
  };
  DeviceIdentity id;
  id.card = text(cap.card, sizeof(cap.card));
  id.driver = text(cap.driver, sizeof(cap.driver));
  id.bus = text(cap.bus_info, sizeof(cap.bus_info));
  id.caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  return id;
}

void CheckCaptureNode(const DeviceIdentity& id, const std::string& device) {
  if (!(id.caps & V4L2_CAP_VIDEO_CAPTURE) && (id.caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE)) {
    DeviceFail(device, "offers only the multi-planar capture API, which arview does not read ('" + id.card + "')");
  }
  if (!(id.caps & V4L2_CAP_VIDEO_CAPTURE)) {
    DeviceFail(device, "not a video capture device ('" + id.card +
                           "'; a webcam usually has several /dev/video nodes, try another)");
  }
}

// ---- Enumeration ----

FrameSizeRates EnumerateRates(V4l2Io& io, int fd, uint32_t fourcc, int width, int height) {
  FrameSizeRates rates;
  rates.width = width;
  rates.height = height;
  for (uint32_t i = 0; i < 64; ++i) {  // bounded: a driver that never says EINVAL cannot hang us
    v4l2_frmivalenum fi{};
    fi.index = i;
    fi.pixel_format = fourcc;
    fi.width = static_cast<uint32_t>(width);
    fi.height = static_cast<uint32_t>(height);
    if (RetryIoctl(io, fd, VIDIOC_ENUM_FRAMEINTERVALS, &fi) != 0) break;
    if (fi.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      if (const double fps = IntervalFps(fi.discrete); fps > 0) rates.fps.push_back(fps);
      continue;
    }
    // Stepwise or continuous: the shortest interval is the highest rate.
    const double fastest = IntervalFps(fi.stepwise.min), slowest = IntervalFps(fi.stepwise.max);
    if (fastest > 0) rates.fps.push_back(fastest);
    if (slowest > 0 && slowest != fastest) rates.fps.push_back(slowest);
    rates.continuous_rates = true;
    break;
  }
  std::sort(rates.fps.rbegin(), rates.fps.rend());
  rates.fps.erase(std::unique(rates.fps.begin(), rates.fps.end()), rates.fps.end());
  return rates;
}

// The sizes worth listing within a stepwise range: its ends and the common sizes inside it.
std::vector<cv::Size> StepwiseSizes(const v4l2_frmsize_stepwise& s) {
  const cv::Size lo(static_cast<int>(s.min_width), static_cast<int>(s.min_height));
  const cv::Size hi(static_cast<int>(s.max_width), static_cast<int>(s.max_height));
  std::vector<cv::Size> sizes = {lo};
  for (const cv::Size common : {cv::Size(640, 480), cv::Size(1280, 720), cv::Size(1920, 1080)}) {
    const bool inside = common.width > lo.width && common.height > lo.height && common.width < hi.width &&
                        common.height < hi.height;
    const bool on_step = (s.step_width == 0 || (common.width - lo.width) % s.step_width == 0) &&
                         (s.step_height == 0 || (common.height - lo.height) % s.step_height == 0);
    if (inside && on_step) sizes.push_back(common);
  }
  if (hi != lo) sizes.push_back(hi);
  return sizes;
}

FormatCapabilities EnumerateFormat(V4l2Io& io, int fd, const v4l2_fmtdesc& desc) {
  FormatCapabilities format;
  format.fourcc = desc.pixelformat;
  format.name = FourccText(desc.pixelformat);
  format.description =
      std::string(reinterpret_cast<const char*>(desc.description), strnlen(reinterpret_cast<const char*>(desc.description), sizeof(desc.description)));
  for (uint32_t i = 0; i < 256; ++i) {
    v4l2_frmsizeenum fs{};
    fs.index = i;
    fs.pixel_format = desc.pixelformat;
    if (RetryIoctl(io, fd, VIDIOC_ENUM_FRAMESIZES, &fs) != 0) break;
    if (fs.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      format.sizes.push_back(EnumerateRates(io, fd, desc.pixelformat, static_cast<int>(fs.discrete.width),
                                            static_cast<int>(fs.discrete.height)));
      continue;
    }
    format.stepwise_sizes = true;
    format.min_size = {static_cast<int>(fs.stepwise.min_width), static_cast<int>(fs.stepwise.min_height)};
    format.max_size = {static_cast<int>(fs.stepwise.max_width), static_cast<int>(fs.stepwise.max_height)};
    for (const cv::Size s : StepwiseSizes(fs.stepwise)) {
      format.sizes.push_back(EnumerateRates(io, fd, desc.pixelformat, s.width, s.height));
    }
    break;
  }
  return format;
}

CameraCapabilities EnumerateCapabilities(V4l2Io& io, int fd) {
  CameraCapabilities caps;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc desc{};
    desc.index = i;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (RetryIoctl(io, fd, VIDIOC_ENUM_FMT, &desc) != 0) break;
    caps.formats.push_back(EnumerateFormat(io, fd, desc));
  }
  return caps;
}

std::vector<ControlMenuItem> EnumerateMenu(V4l2Io& io, int fd, const v4l2_queryctrl& q) {
  std::vector<ControlMenuItem> menu;
  if (q.type != V4L2_CTRL_TYPE_MENU && q.type != V4L2_CTRL_TYPE_INTEGER_MENU) return menu;
  for (int64_t i = q.minimum; i <= q.maximum && i - q.minimum < 256; ++i) {
    v4l2_querymenu m{};
    m.id = q.id;
    m.index = static_cast<uint32_t>(i);
    if (RetryIoctl(io, fd, VIDIOC_QUERYMENU, &m) != 0) continue;  // drivers skip entries they lack
    ControlMenuItem item;
    item.value = i;
    item.name = q.type == V4L2_CTRL_TYPE_MENU
                    ? std::string(reinterpret_cast<const char*>(m.name), strnlen(reinterpret_cast<const char*>(m.name), sizeof(m.name)))
                    : std::to_string(m.value);
    menu.push_back(item);
  }
  return menu;
}

std::vector<CameraControl> EnumerateControls(V4l2Io& io, int fd) {
  std::vector<CameraControl> controls;
  uint32_t id = 0;
  for (int guard = 0; guard < 1024; ++guard) {
    v4l2_queryctrl q{};
    q.id = id | V4L2_CTRL_FLAG_NEXT_CTRL;
    if (RetryIoctl(io, fd, VIDIOC_QUERYCTRL, &q) != 0) break;
    if (q.id <= id) break;  // a driver that does not move on
    id = q.id;
    if (q.type == V4L2_CTRL_TYPE_CTRL_CLASS || (q.flags & V4L2_CTRL_FLAG_DISABLED)) continue;
    CameraControl c;
    c.id = q.id;
    c.name = std::string(reinterpret_cast<const char*>(q.name), strnlen(reinterpret_cast<const char*>(q.name), sizeof(q.name)));
    c.type = q.type;
    c.minimum = q.minimum;
    c.maximum = q.maximum;
    c.step = q.step;
    c.default_value = q.default_value;
    c.flags = q.flags;
    c.menu = EnumerateMenu(io, fd, q);
    if (q.type != V4L2_CTRL_TYPE_BUTTON && !(q.flags & V4L2_CTRL_FLAG_WRITE_ONLY)) {
      v4l2_control value{};
      value.id = q.id;
      if (RetryIoctl(io, fd, VIDIOC_G_CTRL, &value) == 0) {
        c.value_known = true;
        c.value = value.value;
      }
    }
    controls.push_back(std::move(c));
  }
  return controls;
}

uint32_t MjpegOffered(const CameraCapabilities& caps) {
  if (caps.Find(V4L2_PIX_FMT_MJPEG)) return V4L2_PIX_FMT_MJPEG;
  if (caps.Find(V4L2_PIX_FMT_JPEG)) return V4L2_PIX_FMT_JPEG;
  return 0;
}

// Parses the whole of `text` as an integer; false for anything else.
bool ParseInteger(const std::string& text, int64_t& value) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc() && ptr == end && !text.empty();
}

// The exposure menu entry that means automatic: V4L2_EXPOSURE_AUTO where offered; UVC cameras
// offer only manual and aperture priority (their automatic mode).
int64_t AutoExposureMode(const CameraControl& control) {
  for (const int64_t mode : {int64_t{V4L2_EXPOSURE_AUTO}, int64_t{V4L2_EXPOSURE_APERTURE_PRIORITY},
                             int64_t{V4L2_EXPOSURE_SHUTTER_PRIORITY}}) {
    for (const ControlMenuItem& item : control.menu) {
      if (item.value == mode) return mode;
    }
  }
  return control.menu.empty() ? V4L2_EXPOSURE_AUTO : -1;
}

}  // namespace

V4l2Io& SystemV4l2Io() {
  static SystemIo io;
  return io;
}

std::string FourccText(uint32_t f) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((f >> (8 * i)) & 0xff);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

// ---- CameraCapabilities, CameraControl ----

const FormatCapabilities* CameraCapabilities::Find(uint32_t fourcc) const {
  for (const FormatCapabilities& f : formats) {
    if (f.fourcc == fourcc) return &f;
  }
  return nullptr;
}

cv::Size CameraCapabilities::NearestSize(uint32_t fourcc, cv::Size wanted) const {
  const FormatCapabilities* f = Find(fourcc);
  if (f == nullptr || f->sizes.empty()) return {};
  cv::Size best;
  long best_distance = std::numeric_limits<long>::max();
  for (const FrameSizeRates& s : f->sizes) {
    const long distance = std::labs(long{s.width} - wanted.width) + std::labs(long{s.height} - wanted.height);
    if (distance < best_distance) {
      best_distance = distance;
      best = {s.width, s.height};
    }
  }
  return best;
}

const FrameSizeRates* CameraCapabilities::Rates(uint32_t fourcc, cv::Size size) const {
  const FormatCapabilities* f = Find(fourcc);
  if (f == nullptr) return nullptr;
  for (const FrameSizeRates& s : f->sizes) {
    if (s.width == size.width && s.height == size.height) return &s;
  }
  return nullptr;
}

double CameraCapabilities::MaxFps(uint32_t fourcc, cv::Size size) const {
  const FrameSizeRates* rates = Rates(fourcc, size);
  return rates ? rates->MaxFps() : 0.0;
}

bool CameraControl::Inactive() const { return (flags & V4L2_CTRL_FLAG_INACTIVE) != 0; }

std::string CameraControl::TypeName() const {
  switch (type) {
    case V4L2_CTRL_TYPE_INTEGER: return "int";
    case V4L2_CTRL_TYPE_BOOLEAN: return "bool";
    case V4L2_CTRL_TYPE_MENU: return "menu";
    case V4L2_CTRL_TYPE_INTEGER_MENU: return "intmenu";
    case V4L2_CTRL_TYPE_BUTTON: return "button";
    case V4L2_CTRL_TYPE_INTEGER64: return "int64";
    case V4L2_CTRL_TYPE_BITMASK: return "bitmask";
    default: return "type " + std::to_string(type);
  }
}

// ---- DescribeCamera, ListCameras ----

CameraInfo DescribeCamera(const std::string& device, V4l2Io& io) {
  const int fd = OpenDevice(io, device);
  CameraInfo info;
  info.device = device;
  try {
    const DeviceIdentity id = QueryIdentity(io, fd, device);
    CheckCaptureNode(id, device);
    info.card = id.card;
    info.driver = id.driver;
    info.bus = id.bus;
    info.capabilities = EnumerateCapabilities(io, fd);
    info.controls = EnumerateControls(io, fd);
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (RetryIoctl(io, fd, VIDIOC_G_FMT, &fmt) == 0) {
      info.current_size = {static_cast<int>(fmt.fmt.pix.width), static_cast<int>(fmt.fmt.pix.height)};
      info.current_format = FourccText(fmt.fmt.pix.pixelformat);
    }
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (RetryIoctl(io, fd, VIDIOC_G_PARM, &parm) == 0) info.current_fps = IntervalFps(parm.parm.capture.timeperframe);
  } catch (...) {
    io.Close(fd);
    throw;
  }
  io.Close(fd);
  return info;
}

std::vector<CameraListing> ListCameras(const std::filesystem::path& dev, V4l2Io& io) {
  std::vector<std::pair<long, std::string>> nodes;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dev, ec)) {
    const std::string name = entry.path().filename().string();
    int64_t number = 0;
    if (name.rfind("video", 0) != 0 || !ParseInteger(name.substr(5), number)) continue;
    nodes.emplace_back(static_cast<long>(number), entry.path().string());
  }
  std::sort(nodes.begin(), nodes.end());
  std::vector<CameraListing> list;
  for (const auto& [number, path] : nodes) {
    CameraListing item;
    item.device = path;
    try {
      const int fd = OpenDevice(io, path);
      try {
        const DeviceIdentity id = QueryIdentity(io, fd, path);
        item.card = id.card;
        item.driver = id.driver;
        item.bus = id.bus;
        item.capture = (id.caps & V4L2_CAP_VIDEO_CAPTURE) != 0;
      } catch (...) {
        io.Close(fd);
        throw;
      }
      io.Close(fd);
    } catch (const SourceError& e) {
      const std::string what = e.what();
      item.problem = what.substr(std::min(what.size(), path.size() + 2));  // without "<device>: "
    }
    list.push_back(std::move(item));
  }
  return list;
}

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
