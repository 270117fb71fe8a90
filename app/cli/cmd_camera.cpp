// arview camera list                       the V4L2 video nodes with their names
// arview camera info [--device] /dev/videoN formats, sizes, rates and controls of one camera
//
// What `run` and `record` can ask a camera for (--size, --fps, --format, --focus, --exposure)
// depends on what it offers: these say, without streaming from it.

#include <cstdio>
#include <iostream>
#include <sstream>

#include "app/cli/commands.h"
#include "recordings/v4l2_source.h"

namespace arview::app {

namespace {

struct CameraArgs {
  std::string device;
  std::string device_flag;
};

std::string RatesText(const recordings::FrameSizeRates& s) {
  if (s.fps.empty()) return "rates not listed";
  std::ostringstream text;
  if (s.continuous_rates && s.fps.size() == 2) {
    text << s.fps.back() << " to " << s.fps.front() << " fps";
    return text.str();
  }
  for (size_t i = 0; i < s.fps.size(); ++i) text << (i ? ", " : "") << s.fps[i];
  text << " fps";
  return text.str();
}

void PrintFormats(const recordings::CameraCapabilities& caps) {
  std::cout << "formats:\n";
  if (caps.formats.empty()) std::cout << "  none listed\n";
  for (const recordings::FormatCapabilities& f : caps.formats) {
    std::cout << "  " << f.name << " (" << f.description << ")";
    if (f.stepwise_sizes) {
      std::cout << ": any size from " << f.min_size.width << "x" << f.min_size.height << " to " << f.max_size.width
                << "x" << f.max_size.height << ", for example";
    }
    std::cout << "\n";
    if (f.sizes.empty()) std::cout << "    sizes not listed\n";
    for (const recordings::FrameSizeRates& s : f.sizes) {
      std::cout << "    " << s.width << "x" << s.height << ": " << RatesText(s) << "\n";
    }
  }
}

std::string ControlLine(const recordings::CameraControl& c) {
  std::ostringstream line;
  line << "  " << c.name << " (" << c.TypeName() << ")";
  if (c.TypeName() != "button") {
    line << ": " << c.minimum << ".." << c.maximum;
    if (c.step > 1) line << " step " << c.step;
    line << ", default " << c.default_value;
    if (c.value_known) line << ", now " << c.value;
  }
  for (const recordings::ControlMenuItem& item : c.menu) {
    if (c.value_known && item.value == c.value) line << " (" << item.name << ")";
  }
  if (c.Inactive()) line << ", inactive";
  if (!c.menu.empty()) {
    line << "; menu:";
    for (size_t i = 0; i < c.menu.size(); ++i) line << (i ? "," : "") << " " << c.menu[i].value << " " << c.menu[i].name;
  }
  return line.str();
}

void RunInfo(const CameraArgs& args) {
  if (!args.device.empty() && !args.device_flag.empty() && args.device != args.device_flag) {
    throw CommandError("camera info: two devices given (" + args.device + " and --device " + args.device_flag + ")");
  }
  const std::string device = !args.device.empty() ? args.device : args.device_flag;
  if (device.empty()) throw CommandError("camera info: name the device, e.g. 'arview camera info /dev/video0'");
  const recordings::CameraInfo info = recordings::DescribeCamera(device);  // SourceError: one line, from main
  std::cout << info.device << ": " << info.card << " (driver " << info.driver << ", " << info.bus << ")\n";
  if (!info.current_format.empty()) {
    std::cout << "now: " << info.current_size.width << "x" << info.current_size.height << " " << info.current_format;
    if (info.current_fps > 0) std::cout << " at " << info.current_fps << " fps";
    std::cout << "\n";
  }
  PrintFormats(info.capabilities);
  std::cout << "controls:\n";
  if (info.controls.empty()) std::cout << "  none\n";
  for (const recordings::CameraControl& c : info.controls) std::cout << ControlLine(c) << "\n";
}

void RunList() {
  const std::vector<recordings::CameraListing> cameras = recordings::ListCameras();
  if (cameras.empty()) {
    std::cout << "no video devices (/dev/video*): is a camera plugged in?\n";
    return;
  }
  for (const recordings::CameraListing& c : cameras) {
    std::cout << c.device << ": ";
    if (!c.problem.empty()) {
      std::cout << c.problem << "\n";
      continue;
    }
    std::cout << c.card << " (" << c.driver << ", " << c.bus << ")"
              << (c.capture ? "" : ", not a capture node (a webcam's metadata node)") << "\n";
  }
}

}  // namespace

void AddCameraCommand(CLI::App& app) {
  auto args = std::make_shared<CameraArgs>();
  auto* cmd = app.add_subcommand("camera", "List V4L2 cameras and what one offers ('camera list', 'camera info')");
  cmd->require_subcommand(1);
  auto* list = cmd->add_subcommand("list", "The video devices (/dev/video*) with their names");
  list->callback([] { RunList(); });
  auto* info = cmd->add_subcommand("info", "Formats, frame sizes, frame rates and controls (ranges, values) of a camera");
  info->add_option("device", args->device, "V4L2 device, e.g. /dev/video0");
  info->add_option("--device", args->device_flag, "The same, as run and record name it");
  info->callback([args] {
    RunInfo(*args);
  });
}

}  // namespace arview::app
