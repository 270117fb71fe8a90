#include "recordings/v4l2_detail.h"

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
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "base/error.h"

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

}  // namespace

namespace v4l2_detail {

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

}  // namespace v4l2_detail

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

}  // namespace arview::recordings
