#include "app/cli/gl_flags.h"

#include <cstdio>

#include "app/cli/commands.h"

namespace arview::app {

void AddGlFlags(CLI::App* cmd, GlFlags& f) {
  cmd->add_option("--gl", f.backend,
                  "OpenGL: auto (a GPU's EGL device, else Mesa's llvmpipe through EGL, else OSMesa), egl-device, egl "
                  "(Mesa surfaceless) or osmesa; 'arview info gl' shows what this machine has")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "egl-device", "egl", "osmesa"}));
  cmd->add_option("--gl-device", f.device,
                  "EGL device to prefer (its index in 'arview info gl'; default: $ARVIEW_GL_DEVICE, else the first GPU)")
      ->check(CLI::Range(0, 63));
  cmd->add_option("--gl-threads", f.threads, "llvmpipe rasterizer threads, when rendering on the CPU (a GPU ignores it)")
      ->capture_default_str()
      ->check(CLI::Range(0, 16));
  cmd->add_flag("--verbose", f.verbose, "Also say which renderers --gl auto tried before the one it took, and why not them");
}

render::OffscreenOptions ToOffscreenOptions(const GlFlags& f) {
  render::OffscreenOptions o;
  o.backend = render::ParseGlBackend(f.backend);
  // Only auto and egl-device choose among EGL's devices: taken with another, it would be ignored.
  if (f.device >= 0 && o.backend != render::GlBackend::kAuto && o.backend != render::GlBackend::kEglDevice) {
    throw CommandError("--gl-device " + std::to_string(f.device) + " picks an EGL device: it needs --gl auto or "
                       "egl-device (--gl " + f.backend + " renders without one)",
                       2);
  }
  o.threads = f.threads;
  if (f.device >= 0) o.device = f.device;
  o.verbose = f.verbose;
  o.on_note = [](const std::string& note) { std::fprintf(stderr, "note: gl: %s\n", note.c_str()); };
  return o;
}

}  // namespace arview::app
