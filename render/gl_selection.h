#pragma once
// Which OpenGL to render with: the order in which `--gl auto` (and `--gl egl-device`) try the
// machine's renderers, kept apart from the EGL and OSMesa calls so that the choice can be tested
// against any list of devices.
//
// The EGL device platform (EGL_EXT_device_enumeration + EGL_EXT_platform_device) is the way to a
// GPU without a display: NVIDIA's driver lists its GPUs there, Mesa lists one device per DRM
// render node (Intel, AMD, ...) and one software device (llvmpipe). `--gl auto` takes a hardware
// device first (the one named by --gl-device or ARVIEW_GL_DEVICE before the others), then Mesa's
// surfaceless platform, then a software EGL device, then OSMesa: a machine without a GPU renders
// on llvmpipe as before, one with a GPU renders on it without any flag.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/enum_table.h"
#include "render/render_error.h"

namespace arview::render {

// auto: a hardware EGL device, then Mesa's surfaceless platform, a software EGL device, OSMesa;
// osmesa: libOSMesa (llvmpipe); egl: Mesa's surfaceless platform; egl-device: the EGL device
// platform only (hardware devices first).
enum class GlBackend { kAuto, kOsMesa, kEgl, kEglDevice };
constexpr auto EnumNames(GlBackend) {
  return EnumTable<GlBackend, 4>{{{GlBackend::kAuto, "auto"},
                                  {GlBackend::kOsMesa, "osmesa"},
                                  {GlBackend::kEgl, "egl"},
                                  {GlBackend::kEglDevice, "egl-device"}}};
}

// "auto" | "osmesa" | "egl" | "egl-device"; throws RenderError naming the value otherwise.
// (Back: arview::ToString.)
GlBackend ParseGlBackend(const std::string& name);

// Whether a space-separated extension list (EGL's strings) holds `name` as a whole word:
// EGL_EXT_device_drm is not EGL_EXT_device_drm_render_node. A null list holds nothing.
bool HasExtension(const char* list, const char* name);

// What EGL says of one device before a display is made from it.
struct EglDeviceInfo {
  int index = 0;           // position in eglQueryDevicesEXT's list: what --gl-device names
  std::string extensions;  // the device's own extensions (eglQueryDeviceStringEXT)
  std::string drm_node;    // its DRM node, e.g. /dev/dri/renderD128; empty when it has none
  int cuda_device = -1;    // NVIDIA: the CUDA device number (EGL_CUDA_DEVICE_NV), else -1

  // Mesa's llvmpipe device (EGL_MESA_device_software): every other device is taken for hardware.
  bool software() const;
};

enum class GlCandidateKind { kEglDevice, kEglSurfaceless, kOsMesa };

struct GlCandidate {
  GlCandidateKind kind = GlCandidateKind::kOsMesa;
  int device = -1;  // kEglDevice: the device's index
  bool software_device = false;
  // "egl-device 1", "egl (surfaceless)" or "osmesa": how lines and messages name it.
  std::string Name() const;
  bool operator==(const GlCandidate&) const = default;
};

// The device asked for by `--gl-device N` (flag, when given) or else by the environment variable
// ARVIEW_GL_DEVICE; nullopt when neither names one. `environment` is the variable's value (null
// when unset). Throws RenderError naming ARVIEW_GL_DEVICE when it is set but not a device index.
std::optional<int> RequestedGlDevice(std::optional<int> flag, const char* environment);

// The order in which to try: for kAuto the requested device, the other hardware devices, Mesa's
// surfaceless platform, the software devices, OSMesa; for kEglDevice the devices alone, in the
// same order; for kEgl and kOsMesa that one backend. Throws RenderError when `requested` names a
// device the list does not have (saying how many there are, and naming `requested_by`, the flag or
// variable that asked for it, e.g. "ARVIEW_GL_DEVICE=5": a variable set long ago is easily forgotten).
std::vector<GlCandidate> PlanGlCandidates(GlBackend backend, const std::vector<EglDeviceInfo>& devices,
                                          std::optional<int> requested, const std::string& requested_by = "");

struct GlAttempt {
  GlCandidate candidate;
  std::string failure;  // empty for the one taken
};

// Calls try_one on each candidate in turn until one returns without throwing RenderError.
// Returns every attempt, the last one the success. When none succeeds, throws RenderError
// listing each candidate's reason. `devices_note` (e.g. why EGL lists no device) leads that list.
std::vector<GlAttempt> TryGlCandidates(const std::vector<GlCandidate>& plan,
                                       const std::function<void(const GlCandidate&)>& try_one,
                                       const std::string& devices_note = "");

}  // namespace arview::render
