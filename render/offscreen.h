#pragma once
// An offscreen OpenGL 4.5 core context, on the user's GPU where there is one, on Mesa's llvmpipe
// otherwise. Three ways to get one (render/gl_selection.h says in which order `--gl auto` tries
// them):
//  - the EGL device platform (EGL_EXT_platform_device): a GPU without a display (NVIDIA's
//    driver, Mesa's render-node devices) or Mesa's software device;
//  - EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA): Mesa, including Mesa >= 25.1, which
//    removed OSMesa;
//  - OSMesa (libOSMesa, llvmpipe): Debian 12's classic CPU path.
// Both libraries are opened at run time (dlopen), so a machine without one of them still runs
// with the other, and a machine with neither gets one clear error instead of a loader failure.
// The context has no default framebuffer worth drawing into: render/ always draws into its
// own framebuffer objects (RenderTarget).

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/option_check.h"
#include "render/gl_api.h"
#include "render/gl_objects.h"
#include "render/gl_selection.h"
#include "render/render_error.h"

namespace arview::render {

struct OffscreenOptions {
  GlBackend backend = GlBackend::kAuto;
  // llvmpipe rasterizer threads (LP_NUM_THREADS), set before the context is created because
  // tracking shares the cores. 0 rasterizes on the calling thread. Mesa reads the variable
  // once per process and library (OSMesa, or EGL's driver), so the first context fixes it; a
  // later context asking for a different count is refused rather than silently given the old
  // one. The variable is set with setenv, which is not safe against concurrent getenv: create
  // the first context before starting other threads. A GPU ignores it.
  int threads = 1;
  // The EGL device to prefer (--gl-device); unset: ARVIEW_GL_DEVICE's, else none.
  std::optional<int> device;
  // Told, one line each, of every renderer passed over before the one taken ("egl-device 1 not
  // used: its display does not initialise (...)"): all of them when `verbose`, else only a device
  // that was asked for (by `device` or ARVIEW_GL_DEVICE) and could not be used.
  std::function<void(const std::string&)> on_note;
  bool verbose = false;
  // Tests: create EGL contexts as for a driver without EGL_KHR_no_config_context and
  // EGL_KHR_surfaceless_context (a chosen config and a 1x1 pbuffer), the path other drivers take.
  bool egl_config_and_pbuffer = false;

  // Throws OptionError naming the first bad field (base/option_check.h): a `device` with a
  // backend that uses none, negative `threads`. OffscreenContext::Create calls it first.
  void Check(const OptionNames& names = {}) const;
};

// What the context renders on, for start-up lines, --stats and `arview info gl`.
struct RendererInfo {
  GlBackend backend = GlBackend::kOsMesa;  // the one taken (never kAuto)
  int device = -1;                         // the EGL device's index; -1 off the device platform
  std::string vendor, renderer, version;   // GL_VENDOR, GL_RENDERER, GL_VERSION
  bool software = true;                    // llvmpipe or softpipe: rendering on the CPU
  int threads = 0;                         // llvmpipe threads (software only)
};

class OffscreenContext {
 public:
  // Creates and makes current a 4.5 core context; throws RenderError with one clear message
  // when no backend can (naming what was tried and why each failed).
  static std::unique_ptr<OffscreenContext> Create(const OffscreenOptions& options = {});
  virtual ~OffscreenContext() = default;
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  const GlApi& gl() const { return gl_; }
  GlBackend backend() const { return info_.backend; }
  int threads() const { return info_.threads; }
  const RendererInfo& info() const { return info_; }
  // Every candidate tried before this one, with its reason, then this one: `--verbose` prints them.
  const std::vector<GlAttempt>& attempts() const { return attempts_; }
  // E.g. "egl-device 0: llvmpipe (LLVM 15.0.6, 256 bits) by Mesa/X.org, OpenGL 4.5 (Core Profile)
  // Mesa 22.3.6, 2 llvmpipe threads" or "egl-device 1: NVIDIA H200/PCIe/SSE2 by NVIDIA
  // Corporation, OpenGL 4.5.0 NVIDIA 550.54.15".
  std::string Description() const;
  int MaxSamples() const;  // GL_MAX_SAMPLES: 4 on llvmpipe
  // Binds the context to the calling thread (Create binds it to the creating thread); a
  // context is current on one thread at a time, and every GL call needs it current. EGL refuses
  // (EGL_BAD_ACCESS) a context still current on another thread: that thread calls
  // ReleaseCurrent first.
  virtual void MakeCurrent() = 0;
  // Unbinds whatever context is current on the calling thread.
  virtual void ReleaseCurrent() = 0;

 protected:
  OffscreenContext(GlBackend backend, int device, int threads);
  // Loads the entry points and reads the renderer's strings (the context must be current).
  void LoadApi(const GlProcLoader& loader);

 private:
  RendererInfo info_;
  std::vector<GlAttempt> attempts_;
  GlApi gl_;
  // For the whole context, not per target: a fence must stay held after the target that read it
  // is gone, until a later read-back (SceneFences). Freed with the GL context.
  std::unique_ptr<SceneFences> scene_fences_;
};

// The renderer each way would give on this machine: `arview info gl`.
struct GlProbe {
  struct Device {
    EglDeviceInfo device;
    std::optional<RendererInfo> renderer;
    std::string failure;             // why no context could be made on it
  };
  std::string egl_failure;           // why EGL lists no device (no library, no device extensions)
  std::vector<Device> devices;
  std::optional<RendererInfo> surfaceless, osmesa;
  std::string surfaceless_failure, osmesa_failure;
  std::vector<GlAttempt> auto_attempts;  // what `--gl auto` (with `options`' device) would do
  std::string auto_failure;              // when it would find nothing
};
GlProbe ProbeGl(const OffscreenOptions& options);

}  // namespace arview::render
