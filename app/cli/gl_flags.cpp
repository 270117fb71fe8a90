#include "app/cli/gl_flags.h"

#include <cstdio>

#include "app/cli/commands.h"
#include "app/cli/option_flags.h"

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
  o.threads = f.threads;
  if (f.device >= 0) o.device = f.device;
  o.verbose = f.verbose;
  o.on_note = [](const std::string& note) { std::fprintf(stderr, "note: gl: %s\n", note.c_str()); };
  OptionFlags names;
  names.Name("device", "--gl-device");
  names.Name("backend", "--gl");
  names.Name("threads", "--gl-threads");
  names.Check(o, 2);  // flags that do not go together: the usage status
  return o;
}

}  // namespace arview::app
