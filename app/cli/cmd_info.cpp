// arview info gl: what this machine can render with — every EGL device with its vendor, renderer
// and extensions, Mesa's surfaceless platform, OSMesa, and which one `--gl auto` takes.

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "app/cli/commands.h"
#include "render/offscreen.h"

namespace arview::app {

namespace {

struct InfoGlArgs {
  int device = -1;
  bool json = false;
};

std::string RendererLine(const render::RendererInfo& r) {
  return r.renderer + " by " + r.vendor + ", OpenGL " + r.version + (r.software ? " (on the CPU)" : " (GPU)");
}

nlohmann::ordered_json RendererJson(const std::optional<render::RendererInfo>& r, const std::string& failure) {
  if (!r) return {{"usable", false}, {"failure", failure}};
  return {{"usable", true}, {"vendor", r->vendor}, {"renderer", r->renderer}, {"version", r->version}, {"software", r->software}};
}

const render::GlAttempt* Taken(const render::GlProbe& probe) {
  return probe.auto_attempts.empty() || !probe.auto_attempts.back().failure.empty() ? nullptr : &probe.auto_attempts.back();
}

void PrintJson(const render::GlProbe& probe) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json& devices = j["egl_devices"] = nlohmann::ordered_json::array();
  for (const render::GlProbe::Device& d : probe.devices) {
    nlohmann::ordered_json device = {{"index", d.device.index},
                                     {"kind", d.device.software() ? "software" : "hardware"},
                                     {"extensions", d.device.extensions},
                                     {"drm_node", d.device.drm_node},
                                     {"cuda_device", d.device.cuda_device}};
    device.update(RendererJson(d.renderer, d.failure));
    devices.push_back(device);
  }
  if (!probe.egl_failure.empty()) j["egl_devices_failure"] = probe.egl_failure;
  j["egl_surfaceless"] = RendererJson(probe.surfaceless, probe.surfaceless_failure);
  j["osmesa"] = RendererJson(probe.osmesa, probe.osmesa_failure);
  const render::GlAttempt* taken = Taken(probe);
  j["auto"] = taken ? nlohmann::ordered_json(taken->candidate.Name()) : nlohmann::ordered_json(nullptr);
  nlohmann::ordered_json& passed = j["auto_passed_over"] = nlohmann::ordered_json::array();
  for (const render::GlAttempt& a : probe.auto_attempts)
    if (!a.failure.empty()) passed.push_back({{"candidate", a.candidate.Name()}, {"failure", a.failure}});
  if (!probe.auto_failure.empty()) j["auto_failure"] = probe.auto_failure;
  std::printf("%s\n", j.dump(2).c_str());
}

void PrintText(const render::GlProbe& probe) {
  std::printf("EGL devices (--gl egl-device, --gl-device N):");
  if (probe.devices.empty()) std::printf(" none (%s)", probe.egl_failure.c_str());
  std::printf("\n");
  bool any_gpu = false;
  for (const render::GlProbe::Device& d : probe.devices) {
    std::printf("  %d  %-8s  ", d.device.index, d.device.software() ? "software" : "hardware");
    if (d.renderer) {
      std::printf("%s\n", RendererLine(*d.renderer).c_str());
      any_gpu = any_gpu || !d.renderer->software;
    } else {
      std::printf("not usable: %s\n", d.failure.c_str());
    }
    if (!d.device.drm_node.empty()) std::printf("     DRM node %s\n", d.device.drm_node.c_str());
    if (d.device.cuda_device >= 0) std::printf("     CUDA device %d\n", d.device.cuda_device);
    std::printf("     extensions: %s\n", d.device.extensions.empty() ? "(none)" : d.device.extensions.c_str());
  }
  std::printf("Mesa surfaceless (--gl egl): %s\n",
              probe.surfaceless ? RendererLine(*probe.surfaceless).c_str() : ("not usable: " + probe.surfaceless_failure).c_str());
  std::printf("OSMesa (--gl osmesa): %s\n",
              probe.osmesa ? ("present, " + RendererLine(*probe.osmesa)).c_str() : ("absent: " + probe.osmesa_failure).c_str());
  const render::GlAttempt* taken = Taken(probe);
  if (taken == nullptr) {
    std::printf("--gl auto finds nothing: %s\n", probe.auto_failure.c_str());
    throw CommandError("no renderer for --gl auto (above)");
  }
  std::printf("--gl auto takes: %s\n", taken->candidate.Name().c_str());
  for (const render::GlAttempt& a : probe.auto_attempts)
    if (!a.failure.empty()) std::printf("  passed over %s: %s\n", a.candidate.Name().c_str(), a.failure.c_str());
  if (!any_gpu) {
    std::printf("No GPU renderer: arview renders on the CPU (llvmpipe). With a GPU, install its EGL driver "
                "(NVIDIA: the driver's libegl-nvidia0; AMD, Intel: libegl-mesa0) and check here again "
                "(docs/render.md, \"Rendering on a GPU\").\n");
  }
}

}  // namespace

void AddInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "What this machine offers arview");
  cmd->require_subcommand(1);
  auto a = std::make_shared<InfoGlArgs>();
  auto* gl = cmd->add_subcommand(
      "gl", "Every OpenGL renderer arview can use: EGL devices (GPUs and Mesa's software device), Mesa surfaceless, "
            "OSMesa, and which one --gl auto takes");
  gl->add_option("--gl-device", a->device, "As for run and replay: the EGL device --gl auto should prefer")->check(CLI::Range(0, 63));
  gl->add_flag("--json", a->json, "Print JSON instead of text");
  gl->callback([a] {
    render::OffscreenOptions options;
    if (a->device >= 0) options.device = a->device;
    const render::GlProbe probe = render::ProbeGl(options);
    if (a->json) {
      PrintJson(probe);
      if (!Taken(probe)) throw CommandError("no renderer for --gl auto: " + probe.auto_failure);
    } else {
      PrintText(probe);
    }
  });
}

}  // namespace arview::app
