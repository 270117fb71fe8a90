#include "render/gl_selection.h"

#include <charconv>
#include <cstring>

namespace arview::render {

bool HasExtension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::string padded = " " + std::string(list) + " ";
  return padded.find(" " + std::string(name) + " ") != std::string::npos;
}

bool EglDeviceInfo::software() const { return HasExtension(extensions.c_str(), "EGL_MESA_device_software"); }

std::string GlCandidate::Name() const {
  switch (kind) {
    case GlCandidateKind::kEglDevice: return "egl-device " + std::to_string(device);
    case GlCandidateKind::kEglSurfaceless: return "egl (surfaceless)";
    case GlCandidateKind::kOsMesa: return "osmesa";
  }
  return "?";
}

std::optional<int> RequestedGlDevice(std::optional<int> flag, const char* environment) {
  if (flag) return flag;
  if (environment == nullptr || *environment == '\0') return std::nullopt;
  int index = -1;
  const char* end = environment + std::strlen(environment);
  const auto [rest, error] = std::from_chars(environment, end, index);
  if (error != std::errc() || rest != end || index < 0) {
    throw RenderError("ARVIEW_GL_DEVICE='" + std::string(environment) +
                      "' is not an EGL device index (0, 1, ...; 'arview info gl' lists them)");
  }
  return index;
}

namespace {

GlCandidate DeviceCandidate(const EglDeviceInfo& device) {
  return {GlCandidateKind::kEglDevice, device.index, device.software()};
}

// The requested device first, then hardware, then (after `between`) software devices.
void AppendDevices(const std::vector<EglDeviceInfo>& devices, std::optional<int> requested,
                   const std::vector<GlCandidate>& between, std::vector<GlCandidate>* plan) {
  for (const EglDeviceInfo& d : devices)
    if (requested && d.index == *requested) plan->push_back(DeviceCandidate(d));
  for (const EglDeviceInfo& d : devices)
    if (!d.software() && d.index != requested) plan->push_back(DeviceCandidate(d));
  plan->insert(plan->end(), between.begin(), between.end());
  for (const EglDeviceInfo& d : devices)
    if (d.software() && d.index != requested) plan->push_back(DeviceCandidate(d));
}

}  // namespace

std::vector<GlCandidate> PlanGlCandidates(GlBackend backend, const std::vector<EglDeviceInfo>& devices,
                                          std::optional<int> requested, const std::string& requested_by) {
  if (backend == GlBackend::kOsMesa) return {{GlCandidateKind::kOsMesa}};
  if (backend == GlBackend::kEgl) return {{GlCandidateKind::kEglSurfaceless}};
  if (requested) {
    bool listed = false;
    for (const EglDeviceInfo& d : devices) listed = listed || d.index == *requested;
    if (!listed) {
      throw RenderError("GL device " + std::to_string(*requested) +
                        (requested_by.empty() ? std::string() : " (" + requested_by + ")") + " does not exist: EGL lists " +
                        (devices.empty()       ? std::string("no device")
                         : devices.size() == 1 ? std::string("1 (index 0)")
                                               : std::to_string(devices.size()) + " (0-" + std::to_string(devices.size() - 1) + ")") +
                        "; 'arview info gl' lists them");
    }
  }
  std::vector<GlCandidate> plan;
  if (backend == GlBackend::kEglDevice) {
    AppendDevices(devices, requested, {}, &plan);
    return plan;
  }
  AppendDevices(devices, requested, {{GlCandidateKind::kEglSurfaceless}}, &plan);
  plan.push_back({GlCandidateKind::kOsMesa});
  return plan;
}

std::vector<GlAttempt> TryGlCandidates(const std::vector<GlCandidate>& plan,
                                       const std::function<void(const GlCandidate&)>& try_one,
                                       const std::string& devices_note) {
  std::vector<GlAttempt> attempts;
  for (const GlCandidate& candidate : plan) {
    try {
      try_one(candidate);
      attempts.push_back({candidate, ""});
      return attempts;
    } catch (const RenderError& e) {
      attempts.push_back({candidate, e.what()});
    }
  }
  std::string reasons = devices_note;
  for (const GlAttempt& a : attempts) reasons += (reasons.empty() ? "" : "; ") + a.candidate.Name() + ": " + a.failure;
  if (plan.empty() && reasons.empty()) reasons = "nothing to try";
  throw RenderError("no OpenGL 4.5 offscreen context (" + reasons + ")");
}

}  // namespace arview::render
