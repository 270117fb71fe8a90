// arview view: the self-adaptive paper's VR mode (§4.1) and key-camera authoring (§3.2): the
// scene's characters on a floor, a mouse-driven orbit camera whose centre drives the animation
// as a tracked camera does in AR, the view-sphere overlay, and keys to add, remove, undo and
// save key viewpoints. With --orbit and --out, a scripted orbit is rendered without a window.

#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "app/cli/commands.h"
#include "app/cli/gl_flags.h"
#include "app/cli/numeric_flags.h"
#include "app/cli/output_flags.h"
#include "base/atomic_file.h"
#include "app/pipeline/pipeline_report.h"
#include "app/pipeline/stage_stats.h"
#include "app/view/view_orbit.h"
#include "app/view/view_session.h"
#include "video/window.h"
#include "base/cancellation.h"
#include "video/sinks.h"

namespace arview::app {

namespace {

using Clock = std::chrono::steady_clock;

struct ViewArgs {
  std::string scene, character, size = "1280x720", orbit, out, stats, aa = "msaa";
  double fov = 45, fps = 30, fps_limit = 60, seconds = 0;
  GlFlags gl{2};
  bool no_hud = false, no_help = false, json = false;
};


double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

// CPU time of the whole process (every thread, llvmpipe's included), seconds. On a machine
// shared with other work the wall-clock frame rate says how busy the machine was; the CPU time
// per frame says what a frame costs.
double ProcessCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto s = [](const timeval& t) { return t.tv_sec + t.tv_usec * 1e-6; };
  return s(u.ru_utime) + s(u.ru_stime);
}

nlohmann::ordered_json StatsJson(const StageStats& stats, size_t frames, double wall_seconds, double cpu_seconds) {
  nlohmann::ordered_json j;
  j["frames"] = frames;
  j["wall_seconds"] = wall_seconds;
  j["fps"] = wall_seconds > 0 ? frames / wall_seconds : 0;
  j["cpu_ms_per_frame"] = frames > 0 ? 1000 * cpu_seconds / frames : 0;
  for (const auto& [stage, t] : stats.Summaries()) {
    j["stages"][stage] = TimingJson(t);
  }
  return j;
}

std::string StatsText(const StageStats& stats) {
  std::string text;
  for (const auto& [stage, t] : stats.Summaries()) {
    char line[128];
    std::snprintf(line, sizeof line, "  %-8s median %6.2f ms  p95 %6.2f ms\n", stage.c_str(), t.median, t.p95);
    text += line;
  }
  return text;
}

void WriteStats(const ViewArgs& a, const nlohmann::ordered_json& stats) {
  if (!a.stats.empty()) WriteFileAtomically(a.stats, stats.dump(2) + "\n");
}

ViewOptions Options(const ViewArgs& a) {
  ViewOptions o;
  o.size = *ParseFrameSize(a.size);  // checked by --size's validator
  o.fov_deg = a.fov;
  o.character = a.character;
  o.hud = !a.no_hud;
  o.help = !a.no_help;
  o.gl = ToOffscreenOptions(a.gl);
  o.ar.antialiasing = render::ParseAntialiasing(a.aa);
  return o;
}

void RunOrbit(const ViewArgs& a) {
  const OrbitSpec spec = ParseOrbitSpec(a.orbit);
  ViewOptions o = Options(a);
  o.help = false;  // a video for docs: the overlay, not the key help
  ViewSession session(a.scene, o);
  const OrbitState home = session.HomeView();
  const int frames = std::max(1, static_cast<int>(std::lround(spec.seconds * a.fps)));
  PendingOutput pending(a.out);
  const bool file = std::filesystem::path(a.out).has_extension();
  std::unique_ptr<video::FrameSink> sink = video::OpenSink(file ? pending.partial().string() : a.out, o.size, a.fps);
  const ScopedSignalCancellation signals;
  StageStats stats;
  const Clock::time_point start = Clock::now();
  const double cpu0 = ProcessCpuSeconds();
  for (int i = 0; i < frames; ++i) {
    signals.token().ThrowIfCancelled(a.out + " not written");
    const double u = frames > 1 ? static_cast<double>(i) / (frames - 1) : 0.0;
    session.camera().Set(OrbitAt(spec, home, u));
    const cv::Mat frame = session.Render(i / a.fps, &stats);
    const Clock::time_point t0 = Clock::now();
    sink->Write(frame);
    stats.Record("sink", std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  sink->Close();
  if (file) pending.Commit();
  const double wall = Seconds(start);
  std::printf("wrote %s: %d frames (%.1f s at %g fps), rendered at %.1f frames/s\n%srenderer: %s\n", a.out.c_str(),
              frames, frames / a.fps, a.fps, frames / wall, StatsText(stats).c_str(), session.renderer().c_str());
  WriteStats(a, StatsJson(stats, frames, wall, ProcessCpuSeconds() - cpu0));
}

void RunWindow(const ViewArgs& a) {
  const ViewOptions o = Options(a);
  // The display first: without one, say so before loading anything.
  std::unique_ptr<video::DisplayWindow> window =
      video::DisplayWindow::Open("arview view: " + a.scene, o.size, "render without a window with --orbit <spec> --out orbit.mp4");
  ViewSession session(a.scene, o);
  const ScopedSignalCancellation signals;
  StageStats stats;
  const Clock::time_point start = Clock::now();
  const double cpu0 = ProcessCpuSeconds();
  Clock::time_point next = start, last_frame = start, fps_since = start;
  size_t frames = 0, fps_frames = 0;
  const auto period = a.fps_limit > 0 ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1 / a.fps_limit))
                                      : Clock::duration::zero();
  while (!session.quit_requested() && !signals.token().IsCancelled()) {
    const double t = Seconds(start);
    if (a.seconds > 0 && t >= a.seconds) break;
    for (const video::InputEvent& e : window->Poll()) session.Handle(e, t);
    if (session.quit_requested()) break;
    const cv::Mat frame = session.Render(t, &stats);
    const Clock::time_point t0 = Clock::now();
    window->Show(frame);
    const Clock::time_point shown = Clock::now();
    stats.Record("present", std::chrono::duration<double, std::milli>(shown - t0).count());
    if (frames > 0) stats.Record("frame", std::chrono::duration<double, std::milli>(shown - last_frame).count());
    last_frame = shown;
    ++frames, ++fps_frames;
    if (const double dt = std::chrono::duration<double>(shown - fps_since).count(); dt >= 0.5) {
      session.set_fps(fps_frames / dt);
      fps_since = shown, fps_frames = 0;
    }
    if (period > Clock::duration::zero()) {
      next += period;
      if (next < Clock::now()) next = Clock::now();  // behind: do not race to catch up
      std::this_thread::sleep_until(next);
    }
  }
  const double wall = Seconds(start);
  const double cpu = ProcessCpuSeconds() - cpu0;
  if (session.dirty()) {
    std::fprintf(stderr, "view: quit with unsaved key changes (%s not written; s saves)\n", a.scene.c_str());
  }
  nlohmann::ordered_json stats_json = StatsJson(stats, frames, wall, cpu);
  stats_json["present"] = window->PresentMethod();
  stats_json["renderer"] = session.renderer();
  stats_json["size"] = a.size;
  WriteStats(a, stats_json);
  if (a.json) {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(session.StateJson());
    j["stats"] = stats_json;
    std::printf("%s\n", j.dump().c_str());
  } else {
    std::printf("%zu frames in %.1f s: %.1f frames/s (%s, %s), %.2f ms of CPU per frame\n%srenderer: %s\n", frames, wall,
                frames / wall, a.size.c_str(), window->PresentMethod().c_str(), frames ? 1000 * cpu / frames : 0.0,
                StatsText(stats).c_str(), session.renderer().c_str());
  }
}

}  // namespace

void AddViewCommand(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand(
      "view", "VR mode: a mouse-driven camera drives the animation; add, remove and save key viewpoints");
  cmd->add_option("--scene", a->scene, "Scene file (YAML, see docs/anim.md)")->required();
  cmd->add_option("--character", a->character, "Character whose keys are authored (default: the first)");
  cmd->add_option("--size", a->size, "Window or video size")
      ->capture_default_str()
      ->check(FrameSizeCheck({64, 64}, {7680, 4320}));
  cmd->add_option("--fov", a->fov, "Vertical field of view, degrees")->capture_default_str()->check(CLI::Range(10.0, 120.0));
  cmd->add_option("--orbit", a->orbit, "Render a scripted orbit without a window, e.g. azimuth=0..360,elevation=15,seconds=8 (needs --out)");
  cmd->add_option("--out", a->out, "With --orbit: a video file (.mp4, .avi, .mkv) or a PNG folder");
  cmd->add_option("--fps", a->fps, "With --orbit: frames per second of the video")->capture_default_str()->check(CLI::Range(1.0, 240.0));
  cmd->add_option("--fps-limit", a->fps_limit, "Window: at most this many frames per second (0: as fast as it renders)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--seconds", a->seconds, "Window: close after this many seconds (0: when asked)")->check(CLI::Range(0.0, 86400.0));
  cmd->add_flag("--no-hud", a->no_hud, "Start with the overlay hidden (h toggles it)");
  cmd->add_flag("--no-help", a->no_help, "Start with the key help hidden (? toggles it)");
  cmd->add_option("--stats", a->stats, "Write frame rate and per-stage timings as JSON")->check(OutputFileCheck());
  cmd->add_flag("--json", a->json, "Window: print the final state (camera, viewpoint, weights, keys, timings) as JSON");
  cmd->add_option("--aa", a->aa, "Antialiasing: msaa (4x) or none")->capture_default_str();
  AddGlFlags(cmd, a->gl);
  cmd->callback([a] {
    if (a->orbit.empty() != a->out.empty()) throw CommandError("--orbit and --out go together: --orbit <spec> --out orbit.mp4");
    RequireDistinctOutputs({{"--out", a->out}, {"--stats", a->stats}});
    if (!a->orbit.empty()) RunOrbit(*a);
    else RunWindow(*a);
  });
}

}  // namespace arview::app
