// arview run: the whole pipeline live on a V4L2 camera (a webcam, or an HMD's camera).

#include <cstdio>

#include "app/session/ar_session.h"
#include "app/cli/audio_flags.h"
#include "app/cli/camera_flags.h"
#include "app/cli/commands.h"
#include "app/cli/output_flags.h"
#include "app/cli/first_run_figure.h"
#include "app/pipeline/pipeline_report.h"
#include "app/cli/numeric_flags.h"
#include "app/cli/session_flags.h"
#include "app/cli/dialogue_flags.h"
#include "base/cancellation.h"
#include "map/map_file.h"
#include "recordings/v4l2_source.h"
#include "render/offscreen.h"
#include "tracker/working_resolution.h"
#include "video/sinks.h"

namespace arview::app {

namespace {

struct RunArgs {
  std::string device = "/dev/video0", map_dir, out = "window";
  std::string camera_file;  // --camera: the device's calibration when it is not the map's camera
  std::string audio_out = "default";
  CameraFlags camera;
  SessionFlags session;
  DialogueFlags dialogue;
};

std::string SizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// A camera calibrated at one size works at another of the same aspect (its intrinsics scale
// exactly); across aspects the sensor is cropped differently and the calibration does not hold.
// `whose`: the calibration's owner, "the map's camera" or "--camera's calibration".
void RequireSameAspect(cv::Size calibrated, cv::Size used, const std::string& what, const std::string& whose,
                       const std::string& file) {
  const double cross = static_cast<double>(used.width) * calibrated.height - static_cast<double>(used.height) * calibrated.width;
  if (std::abs(cross) <= 0.005 * static_cast<double>(used.width) * calibrated.height) return;
  throw CommandError(what + ": another aspect than " + whose + " (" + SizeText(calibrated) + ", " + file +
                     "); a camera calibrated at one aspect cannot be scaled to another (calibrate this camera at this "
                     "size and give it with --camera)");
}

}  // namespace

void AddRunCommand(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand("run", "Run the whole pipeline live on a V4L2 camera or HMD");
  cmd->add_option("--device", a->device, "V4L2 capture device")->capture_default_str();
  cmd->add_option("--map", a->map_dir, "Map folder written by 'arview map' (with any camera)")->required();
  cmd->add_option("--camera", a->camera_file,
                  "The device's calibration (camera.yaml from 'arview calibrate') when it is not the camera the map "
                  "was made with: frames are tracked with it (default: the map's camera)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", a->out, "Output: 'window' (Esc or q stops), a video file, or a PNG folder")->capture_default_str();
  AddCameraFlags(cmd, a->camera,
                 "default: the size of --camera's calibration, else of the map's camera; another of the same aspect "
                 "scales the calibration exactly");
  AddSessionFlags(cmd, a->session);
  AddAudioOutFlag(cmd, a->audio_out);
  AddDialogueFlags(cmd, a->dialogue, DialogueInput::kMicrophone);
  cmd->callback([a] {
    const bool to_file = !video::IsWindowTarget(a->out) && a->out != "null";
    RequireDistinctOutputs(
        {{"--out", to_file ? a->out : ""}, {"--trajectory", a->session.trajectory}, {"--stats", a->session.stats}});
    SessionOptions o;
    o.command_start = Clock::now();
    ApplySessionFlags(a->session, /*live_source=*/true, o);
    ApplyDialogueFlags(a->dialogue, video::IsWindowTarget(a->out), o);
    // No per-frame record and no pose kept (--stats and --trajectory stream them to disk): a
    // long run's memory stays flat.
    o.pipeline.keep_frame_logs = false;
    o.pipeline.keep_trajectory = false;
    o.sink = a->out;
    o.pipeline.drop_frames = true;  // live: never fall behind the camera
    // An unplugged or stalled camera ends the session with what it has: the video, the
    // trajectory and the stats so far are written, then the fault is the command's error.
    o.pipeline.end_on_source_fault = true;
    o.pipeline.on_source_note = [](const std::string& note) { std::fprintf(stderr, "\nnote: %s\n", note.c_str()); };
    const ScopedSignalCancellation signals;
    o.cancel = signals.token();
    o.cancel_ends_normally = true;  // Ctrl-C is how a live session ends

    // The camera delivers its calibration's size (--camera's, else the map's camera's), or --size
    // where its aspect is the calibration's (which is then scaled exactly); the map is read first
    // to know it. The frames are tracked with that calibration, in the map's world.
    recordings::V4l2Options v4l2;
    ApplyCameraFlags(a->camera, v4l2);
    v4l2.cancel = signals.token();
    const map::Map map = LoadSessionMap(a->map_dir, a->session.room);
    const bool own_camera = !a->camera_file.empty();
    const calib::Camera calibration = own_camera ? calib::LoadCamera(a->camera_file) : map.camera;
    const std::string whose = own_camera ? "--camera's calibration" : "the map's camera";
    const std::string calibration_file = own_camera ? a->camera_file : a->map_dir;
    v4l2.focus = SessionFocus(a->camera, calibration);
    const cv::Size wanted = a->camera.size.empty() ? calibration.Size() : *ParseFrameSize(a->camera.size);
    RequireSameAspect(calibration.Size(), wanted, "--size " + a->camera.size, whose, calibration_file);
    v4l2.width = wanted.width;
    v4l2.height = wanted.height;
    recordings::V4l2Source source(a->device, v4l2);
    std::fprintf(stderr, "%s (Ctrl-C stops)\n", source.GrantedLine().c_str());
    for (const std::string& note : source.notes()) std::fprintf(stderr, "note: %s\n", note.c_str());
    const std::string calibrated_where = own_camera ? a->camera_file : "the map " + a->map_dir;
    if (const std::string mismatch = FocusMismatch(source, calibration, calibrated_where); !mismatch.empty()) {
      std::fprintf(stderr, "warning: %s\n", mismatch.c_str());
    } else if (calibration.focus && a->camera.focus.empty()) {
      std::fprintf(stderr, "note: focus held at %lld, where %s was calibrated\n", static_cast<long long>(*calibration.focus),
                   whose.c_str());
    }
    o.frame_camera = calibration;
    if (source.size() != calibration.Size()) {
      RequireSameAspect(calibration.Size(), source.size(), a->device + " delivers " + SizeText(source.size()), whose,
                        calibration_file);
      o.frame_camera = tracker::ScaleCamera(calibration, source.size().width, source.size().height);
      std::fprintf(stderr, "note: %s, calibrated at %s, is scaled exactly to %s (fx %.1f -> %.1f)\n", whose.c_str(),
                   SizeText(calibration.Size()).c_str(), SizeText(source.size()).c_str(), calibration.fx,
                   o.frame_camera->fx);
    }
    if (o.scene_file.empty() && !a->session.no_figure) o.first_view = FirstRunFigure(map, a->map_dir);
    // The scene's lines played live (--audio-out), and written into a video file.
    const audio::OpenedAudioOut sound = OpenAudioOutForScene(a->audio_out, o.scene_file);
    o.sound_out = sound.player.get();
    o.audio_track = true;
    const SessionResult result = RunSession(source, source.size(), map, a->map_dir, o);
    std::printf("%s%s%s", PipelineReportText(result.report).c_str(), result.loss_advice.c_str(),
                SoundSummaryText(result.sound).c_str());
    std::printf("output: %s\n", result.output.c_str());
    if (result.seconds_to_first_output >= 0) {
      std::printf("first frame shown %.2f s after the command started (start-up: the tracker %.2f s beside the "
                  "characters %.2f s, the renderer %.2f s and its warm-up %.2f s; then the camera's first frame and "
                  "its render)\n",
                  result.seconds_to_first_output, result.tracker_seconds, result.characters_seconds,
                  result.renderer_seconds, result.warmup_seconds);
      if (result.seconds_to_first_localized_output >= 0) {
        std::printf("first frame localized, the characters placed, %.2f s after the command started\n",
                    result.seconds_to_first_localized_output);
      }
    }
    if (!result.report.source_fault.empty()) {
      std::string kept = video::IsWindowTarget(a->out) || a->out == "null" ? "" : a->out;
      for (const std::string& file : {o.trajectory_out.string(), o.stats_out.string()}) {
        if (!file.empty()) kept += (kept.empty() ? "" : ", ") + file;
      }
      throw Error(result.report.source_fault + (kept.empty() ? std::string() : "; kept what was recorded: " + kept));
    }
  });
}

}  // namespace arview::app
