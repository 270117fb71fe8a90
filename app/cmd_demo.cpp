// arview demo: everything on the embedded default, with no camera and no downloads.
//
// The project renders its own room (a hand-held walk twice round it, exact ground truth), maps
// the first lap with COLMAP, places the humanoid BCN_Epileptic (Debian assimp-testmodels) on the
// floor with eight look-at keys, replays the second lap — which holds the path's fast turn —
// through the whole pipeline (tracking, view-adaptive animation, rendering, compositing) into an
// MP4, and judges the tracking against the ground truth.

#include <cstdio>
#include <filesystem>

#include "app/ar_session.h"
#include "app/commands.h"
#include "base/atomic_file.h"
#include "app/pipeline_report.h"
#include "app/place_character.h"
#include "app/progress.h"
#include "base/cancellation.h"
#include "mapping/colmap_pipeline.h"
#include "recordings/accuracy.h"
#include "render/synth_room.h"

namespace arview::app {

namespace {

namespace fs = std::filesystem;

struct DemoArgs {
  std::string out;
  std::string work = "arview-demo";
  int frames = 1340;  // two laps of the room path (one lap: 22.2 s at 30 fps)
  int map_every = 7;
  std::string character = "/usr/share/assimp/models/X/BCN_Epileptic.X";
  std::string gl = "auto";
  int gl_threads = 1;
  bool hmd = false;
};

void Step(int n, const std::string& what) { std::printf("\n[%d/6] %s\n", n, what.c_str()); std::fflush(stdout); }

recordings::Recording RenderWalk(const fs::path& dir, int frames, std::uint64_t seed, const render::OffscreenOptions& gl,
                                 const CancellationToken& cancel) {
  if (fs::exists(dir / "frames.txt")) {
    try {
      recordings::Recording existing = recordings::LoadRecording(dir);
      if (static_cast<int>(existing.frames.size()) == frames) {
        std::printf("  %s already holds %d frames: reused\n", dir.c_str(), frames);
        return existing;
      }
    } catch (const std::exception&) {
      // Not a usable recording: render it again.
    }
  }
  render::SynthRoomOptions o;
  o.out = dir;
  o.frames = frames;
  o.seed = seed;
  o.overwrite = true;
  o.gl = gl;  // Mesa reads the thread count once per process: the same as for the replay
  Progress progress("  rendering");
  const render::SynthRoomReport r = render::SynthesizeRoom(o, [&](int done, int total) {
    cancel.ThrowIfCancelled("stopped rendering the room after " + std::to_string(done) + " of " +
                            std::to_string(total) + " frames; a re-run renders it again");
    progress.Update(done, total);
  });
  progress.Finish();
  std::printf("  %d frames at 640x480 with exact ground truth -> %s\n", r.frames, dir.c_str());
  return recordings::LoadRecording(dir);
}

}  // namespace

void AddDemoCommand(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  auto* cmd = app.add_subcommand("demo", "Run everything on the embedded default scene (no camera, no downloads)");
  cmd->add_option("--out", a->out, "The augmented video (default: <work>/demo.mp4)");
  cmd->add_option("--work", a->work, "Folder for the recordings, the map and the reports (reused by a re-run)")
      ->capture_default_str();
  cmd->add_option("--frames", a->frames, "Frames of the walk through the room (30 fps); the first half is mapped")
      ->capture_default_str()
      ->check(CLI::Range(60, 6000));
  cmd->add_option("--map-every", a->map_every, "Map from every N-th frame of the first half")
      ->capture_default_str()
      ->check(CLI::Range(1, 30));
  cmd->add_option("--character", a->character, "Character asset")->capture_default_str();
  cmd->add_option("--gl", a->gl, "OpenGL backend: auto, osmesa or egl")->capture_default_str();
  cmd->add_option("--gl-threads", a->gl_threads, "llvmpipe rasterizer threads")->capture_default_str()->check(CLI::Range(0, 16));
  cmd->add_flag("--hmd", a->hmd, "Side-by-side stereo output");
  cmd->callback([a] {
    const fs::path work = a->work;
    fs::create_directories(work);
    const fs::path out = a->out.empty() ? work / "demo.mp4" : fs::path(a->out);
    render::OffscreenOptions gl;
    gl.backend = render::ParseGlBackend(a->gl);
    gl.threads = a->gl_threads;
    const ScopedSignalCancellation signals;

    Step(1, "Rendering a walk twice round the room, with exact ground truth");
    const recordings::Recording walk = RenderWalk(work / "room", a->frames, 1, gl, signals.token());
    const int half = a->frames / 2;

    Step(2, "Checking the recording");
    std::printf("  frames 0-%d (first lap) build the map; frames %d-%d (second lap, with the fast turn) are tracked\n",
                half - 1, half, a->frames - 1);

    Step(3, "Mapping the first lap with COLMAP");
    mapping::MapBuildOptions map_options;
    map_options.frames_spec = "0-" + std::to_string(half - 1) + ":" + std::to_string(a->map_every);
    map_options.matcher = mapping::MatcherKind::kSequential;
    // A rendered room at 640x480 has plenty of texture: 2048 features a frame map it, and keep
    // COLMAP's matching (quadratic in the feature count) to seconds.
    map_options.max_num_features = 2048;
    map_options.cancel = signals.token();
    Progress map_progress("  colmap");
    std::string stage_shown;
    mapping::MapBuildCallbacks callbacks;
    callbacks.progress = [&](const std::string& stage, int done, int total) {
      if (signals.token().IsCancelled()) return;  // after a Ctrl-C: only the one line
      if (stage != stage_shown) {
        map_progress.Finish();
        map_progress = Progress("  colmap " + stage);
        stage_shown = stage;
      }
      map_progress.Update(done, total > 0 ? total : done);
    };
    callbacks.note = [&](const std::string& message) { std::printf("  %s\n", message.c_str()); };
    const mapping::MapBuildResult built = mapping::BuildMap(walk, work / "map", map_options, callbacks);
    map_progress.Finish();
    double map_seconds = 0;
    for (const auto& t : built.timings) map_seconds += t.seconds;
    std::printf("  %zu of %zu frames registered, %zu points, %.1f s\n", built.map.keyframes.size(),
                built.selected_frames.size(), built.map.points.size(), map_seconds);

    Step(4, "Placing the character on the floor with 8 look-at keys");
    PlaceCharacterOptions place_options;
    place_options.base_clip = "rest";  // BCN_Epileptic's only clip is a seizure on the floor
    PlacedCharacter placed = PlaceCharacter(built.map, a->character, place_options);
    placed.comment = "arview demo: " + placed.asset.filename().string() + " on the floor of the rendered room";
    const fs::path scene = work / "scene.yaml";
    WriteSceneFile(placed, scene);
    std::printf("  %s at (%.3f, %.3f, %.3f) in map units -> %s\n", placed.name.c_str(), placed.anchor.position.x(),
                placed.anchor.position.y(), placed.anchor.position.z(), scene.c_str());

    Step(5, "Replaying the second lap: track, animate, render, composite");
    SessionOptions session;
    session.scene_file = scene;
    PendingOutput video(out);
    session.sink = video.sink_target();
    session.sink_fps = MedianFrameRate(walk.frames);
    session.trajectory_out = work / "trajectory.txt";
    session.stats_out = work / "stats.json";
    session.compositor.gl = gl;
    session.compositor.hmd = a->hmd;
    session.expected_frames = a->frames - half;
    session.cancel = signals.token();
    session.output_name = out.string();
    recordings::ReplayOptions replay;
    for (int i = half; i < a->frames; ++i) replay.frames.push_back(i);
    recordings::RecordingSource source(walk, replay);
    const SessionResult result = RunSession(source, walk.camera.Size(), built.map, (work / "map").string(), session);
    video.Commit();
    std::printf("%s", PipelineReportText(result.report).c_str());

    Step(6, "Tracking accuracy against the exact ground truth");
    // The map lives in COLMAP's frame; the alignment to the room is fitted on the map's
    // keyframes (first lap), never on the frames being judged (second lap).
    recordings::Trajectory keyframes;
    for (const auto& k : built.map.keyframes) keyframes.push_back({k.timestamp, k.pose});
    const recordings::Sim3 to_room =
        recordings::FitAlignment(keyframes, *walk.groundtruth, recordings::AlignMode::kSim3, 1e-3);
    recordings::AccuracyOptions accuracy;
    accuracy.align = recordings::AlignMode::kNone;
    accuracy.max_dt = 1e-3;
    const recordings::Trajectory second_lap(walk.groundtruth->begin() + half, walk.groundtruth->end());
    const recordings::AccuracyReport report = recordings::EvaluateTrajectory(
        recordings::TransformTrajectory(result.report.trajectory, to_room), second_lap, accuracy);
    recordings::PlotTrajectories(report, second_lap, work / "trajectory.png");
    std::printf("  localized %zu of %zu frames (%.1f%%)\n", result.report.frames_localized, result.report.frames_processed,
                100.0 * result.report.frames_localized / std::max<size_t>(1, result.report.frames_processed));
    std::printf("  camera centre error: median %.1f mm, RMSE %.1f mm, max %.1f mm; rotation median %.2f deg\n",
                1000 * report.ate.median, 1000 * report.ate.rmse, 1000 * report.ate.max, report.rotation_deg.median);
    std::printf("  throughput %.1f frames per second, end-to-end latency median %.1f ms\n", result.report.fps,
                result.report.stages.count("latency") ? result.report.stages.at("latency").median : 0.0);
    std::printf("\nwrote %s\n      %s (plot), %s, %s, %s\n", out.c_str(), (work / "trajectory.png").c_str(),
                (work / "trajectory.txt").c_str(), (work / "stats.json").c_str(), scene.c_str());
  });
}

}  // namespace arview::app
