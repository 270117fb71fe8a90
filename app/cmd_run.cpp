// arview run: the whole pipeline live on a V4L2 camera (a webcam, or an HMD's camera).

#include <cstdio>

#include "app/ar_session.h"
#include "app/commands.h"
#include "app/interrupt.h"
#include "app/pipeline_report.h"
#include "mapping/map_file.h"
#include "recordings/v4l2_source.h"
#include "render/offscreen.h"

namespace arview::app {

void AddRenderingFlags(CLI::App* cmd, std::string& gl, int& gl_threads, bool& hmd, double& ipd, double& hold,
                       double& fade);

namespace {

struct RunArgs {
  std::string device = "/dev/video0", map_dir, scene, out = "window", trajectory, stats, format = "auto", gl = "auto";
  bool hmd = false;
  double ipd = 0.064, hold = 0.5, fade = 1.0;
  int gl_threads = 1;
};

}  // namespace

void AddRunCommand(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand("run", "Run the whole pipeline live on a V4L2 camera or HMD");
  cmd->add_option("--device", a->device, "V4L2 capture device")->capture_default_str();
  cmd->add_option("--map", a->map_dir, "Map folder written by 'arview map' (made with this camera)")->required();
  cmd->add_option("--scene", a->scene, "Scene file (see 'arview place')");
  cmd->add_option("--out", a->out, "Output: 'window' (Esc or q stops), a video file, or a PNG folder")->capture_default_str();
  cmd->add_option("--format", a->format, "Camera pixel format: auto, yuyv or mjpeg")->capture_default_str();
  cmd->add_option("--trajectory", a->trajectory, "Also write the tracked poses (TUM, camera-to-world)");
  cmd->add_option("--stats", a->stats, "Also write per-stage timings and per-frame tracking as JSON");
  AddRenderingFlags(cmd, a->gl, a->gl_threads, a->hmd, a->ipd, a->hold, a->fade);
  cmd->callback([a] {
    SessionOptions o;
    o.scene_file = a->scene;
    o.sink = a->out;
    o.trajectory_out = a->trajectory;
    o.stats_out = a->stats;
    o.compositor.gl.backend = render::ParseGlBackend(a->gl);
    o.compositor.gl.threads = a->gl_threads;
    o.compositor.hmd = a->hmd;
    o.compositor.ipd_m = a->ipd;
    o.fade = {a->hold, a->fade};
    o.pipeline.drop_frames = true;  // live: never fall behind the camera
    InterruptFlag interrupt;
    o.stop = interrupt.flag();

    // The camera must deliver the map camera's size; the map is read first to know it.
    recordings::V4l2Options v4l2;
    v4l2.format = a->format;
    v4l2.stop = interrupt.flag();
    const mapping::Map map = mapping::LoadMap(a->map_dir);
    v4l2.width = map.camera.width;
    v4l2.height = map.camera.height;
    recordings::V4l2Source source(a->device, v4l2);
    std::fprintf(stderr, "%s: %s, %dx%d %s (Ctrl-C stops)\n", a->device.c_str(), source.CardName().c_str(),
                 source.size().width, source.size().height, source.FormatName().c_str());
    const SessionResult result = RunSession(source, source.size(), map, a->map_dir, o);
    std::printf("%s", PipelineReportText(result.report).c_str());
    std::printf("renderer: %s\n", result.renderer.c_str());
  });
}

}  // namespace arview::app
