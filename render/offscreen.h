#pragma once
// An offscreen OpenGL 4.5 core context on Mesa, with two backends:
//  - OSMesa (libOSMesa, llvmpipe): the default on Debian 12;
//  - EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA): for Mesa >= 25.1, which removed OSMesa.
// Both libraries are opened at run time (dlopen), so a machine without one of them still runs
// with the other, and a machine with neither gets one clear error instead of a loader failure.
// The context has no default framebuffer worth drawing into: render/ always draws into its
// own framebuffer objects (RenderTarget).

#include <memory>
#include <stdexcept>
#include <string>

#include "base/enum_table.h"
#include "base/error.h"
#include "render/gl_api.h"

namespace arview::render {

// Anything in render/ that cannot be done: no GL, a shader that does not compile, bad input.
struct RenderError : Error {
  using Error::Error;
};

enum class GlBackend { kAuto, kOsMesa, kEgl };
constexpr auto EnumNames(GlBackend) {
  return EnumTable<GlBackend, 3>{{{GlBackend::kAuto, "auto"}, {GlBackend::kOsMesa, "osmesa"}, {GlBackend::kEgl, "egl"}}};
}

// "auto" | "osmesa" | "egl"; throws RenderError naming the value otherwise. (Back: arview::ToString.)
GlBackend ParseGlBackend(const std::string& name);

struct OffscreenOptions {
  GlBackend backend = GlBackend::kAuto;  // auto: OSMesa, then EGL if OSMesa is unavailable
  // llvmpipe rasterizer threads (LP_NUM_THREADS), set before the context is created because
  // tracking shares the cores. 0 rasterizes on the calling thread. Mesa reads the variable
  // once per process and backend, so the first context fixes it; a later context asking for
  // a different count is refused rather than silently given the old one. The variable is set
  // with setenv, which is not safe against concurrent getenv: create the first context before
  // starting other threads.
  int threads = 1;
};

class OffscreenContext {
 public:
  // Creates and makes current a 4.5 core context; throws RenderError with one clear message
  // when no backend can (naming what was tried and why it failed).
  static std::unique_ptr<OffscreenContext> Create(const OffscreenOptions& options = {});
  virtual ~OffscreenContext() = default;
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  const GlApi& gl() const { return gl_; }
  GlBackend backend() const { return backend_; }
  int threads() const { return threads_; }
  // E.g. "osmesa: llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6, 2 llvmpipe threads".
  std::string Description() const;
  int MaxSamples() const;  // GL_MAX_SAMPLES: 4 on llvmpipe
  // Binds the context to the calling thread (Create binds it to the creating thread); a
  // context is current on one thread at a time, and every GL call needs it current.
  virtual void MakeCurrent() = 0;

 protected:
  OffscreenContext(GlBackend backend, int threads) : backend_(backend), threads_(threads) {}
  void LoadApi(const GlProcLoader& loader);

 private:
  GlBackend backend_;
  int threads_;
  GlApi gl_;
};

}  // namespace arview::render
