#pragma once
// What recordings/v4l2_device.cpp (the device's identity, formats, rates and controls) shares with
// recordings/v4l2_source.cpp (streaming): the ioctl helpers and the enumerations V4l2Source's
// set-up uses. Not part of the module's interface.

#include <linux/videodev2.h>

#include <cstdint>
#include <string>
#include <vector>

#include "recordings/v4l2_source.h"

namespace arview::recordings::v4l2_detail {

std::string ErrnoText(int err);
[[noreturn]] void DeviceFail(const std::string& device, const std::string& problem);
// ioctl, retried while a signal interrupts it.
int RetryIoctl(V4l2Io& io, int fd, unsigned long request, void* arg);
std::string FpsText(double fps);                   // "30", "7.5", "29.97"
std::string SizeText(int width, int height);       // "640x480"
double IntervalFps(const v4l2_fract& interval);
int OpenDevice(V4l2Io& io, const std::string& device);

struct DeviceIdentity {
  std::string card, driver, bus;
  uint32_t caps = 0;  // the node's own capabilities
};
DeviceIdentity QueryIdentity(V4l2Io& io, int fd, const std::string& device);
void CheckCaptureNode(const DeviceIdentity& id, const std::string& device);
CameraCapabilities EnumerateCapabilities(V4l2Io& io, int fd);
std::vector<CameraControl> EnumerateControls(V4l2Io& io, int fd);
uint32_t MjpegOffered(const CameraCapabilities& caps);
bool ParseInteger(const std::string& text, int64_t& value);
int64_t AutoExposureMode(const CameraControl& control);

}  // namespace arview::recordings::v4l2_detail

// Only the two files above include this header: they use the helpers unqualified.
namespace arview::recordings {
using v4l2_detail::DeviceIdentity;
using v4l2_detail::ErrnoText;
using v4l2_detail::DeviceFail;
using v4l2_detail::RetryIoctl;
using v4l2_detail::FpsText;
using v4l2_detail::SizeText;
using v4l2_detail::IntervalFps;
using v4l2_detail::OpenDevice;
using v4l2_detail::QueryIdentity;
using v4l2_detail::CheckCaptureNode;
using v4l2_detail::EnumerateCapabilities;
using v4l2_detail::EnumerateControls;
using v4l2_detail::MjpegOffered;
using v4l2_detail::ParseInteger;
using v4l2_detail::AutoExposureMode;
}  // namespace arview::recordings
