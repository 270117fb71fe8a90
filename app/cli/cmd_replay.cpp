// arview replay: the whole pipeline on a recording (track, animate, render, composite).

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/session/ar_session.h"
#include "app/cli/audio_flags.h"
#include "app/cli/commands.h"
#include "app/cli/output_flags.h"
#include "app/cli/first_run_figure.h"
#include "base/atomic_file.h"
#include "app/cli/session_flags.h"
#include "app/cli/dialogue_flags.h"
#include "base/cancellation.h"
#include "app/pipeline/pipeline_report.h"
#include "map/map_file.h"
#include "recordings/recording.h"
#include "render/offscreen.h"
#include "video/sinks.h"

namespace arview::app {

namespace {

struct ReplayArgs {
  std::string recording, map_dir, out, frames;
  std::string audio_out = "default";  // played only with --paced
  bool paced = false;
  long loop = 1;
  int read_ahead = recordings::ReplayOptions{}.read_ahead;
  SessionFlags session;
  DialogueFlags dialogue;
};

}  // namespace

void AddReplayCommand(CLI::App& app) {
  auto a = std::make_shared<ReplayArgs>();
  auto* cmd = app.add_subcommand("replay", "Run the whole pipeline on a recording: track, animate, render, composite");
  cmd->add_option("recording", a->recording, "Recording folder")->required();
  cmd->add_option("--map", a->map_dir, "Map folder written by 'arview map'")->required();
  cmd->add_option("--out", a->out, "Output: a video file (.mp4, .avi, .mkv), a PNG folder, 'window', or 'null' (frames discarded)")->required();
  cmd->add_option("--frames", a->frames, "Frames to replay, e.g. 1-46:2 (default: all)");
  cmd->add_flag("--paced", a->paced, "Deliver frames at the recorded rate, dropping frames when a stage is slower");
  cmd->add_option("--loop", a->loop,
                  "Replay the frames this many times in a row (timestamps keep increasing; a soak test: "
                  "--loop 100 --out null)")
      ->capture_default_str()
      ->check(CLI::Range(1L, 100000000L));
  CLI::Option* read_ahead = cmd->add_option("--read-ahead", a->read_ahead,
                  "With --paced: frames read and decoded this many ahead of their time, as a camera's driver holds "
                  "frames (0: each frame read when the one before it is taken)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  AddSessionFlags(cmd, a->session);
  AddAudioOutFlag(cmd, a->audio_out);
  AddDialogueFlags(cmd, a->dialogue, DialogueInput::kWavFile);
  cmd->callback([a, read_ahead] {
    // An unpaced replay reads each frame when the tracker takes it: there is no ahead.
    if (read_ahead->count() > 0 && !a->paced)
      throw CommandError("--read-ahead needs --paced: an unpaced replay reads each frame when the tracker takes it", 2);
    const bool to_file = !video::IsWindowTarget(a->out) && a->out != "null";
    RequireDistinctOutputs(
        {{"--out", to_file ? a->out : ""}, {"--trajectory", a->session.trajectory}, {"--stats", a->session.stats}});
    const ScopedSignalCancellation signals;
    const recordings::Recording recording = recordings::LoadRecording(a->recording);
    recordings::ReplayOptions replay;
    replay.paced = a->paced;
    replay.read_ahead = a->read_ahead;
    replay.loop = a->loop > 1;
    replay.passes = a->loop;
    if (!a->frames.empty()) replay.frames = recordings::ParseFrameSpec(a->frames, static_cast<int>(recording.frames.size()));
    const long expected = a->loop * (replay.frames.empty() ? static_cast<long>(recording.frames.size())
                                                           : static_cast<long>(replay.frames.size()));

    SessionOptions o;
    ApplySessionFlags(a->session, /*live_source=*/a->paced, o);
    ApplyDialogueFlags(a->dialogue, video::IsWindowTarget(a->out), o);
    // No per-frame record and no pose kept (--stats and --trajectory stream them to disk): a
    // long run's memory stays flat.
    o.pipeline.keep_frame_logs = false;
    o.pipeline.keep_trajectory = false;
    o.pipeline.drop_frames = a->paced;
    o.expected_frames = expected;
    o.sink_fps = MedianFrameRate(recording.frames);
    o.cancel = signals.token();
    o.output_name = a->out;
    // Shown in a window, Ctrl-C is how a person ends a replay, as Esc is, and so it is for a
    // replay into null (a soak or a measurement, which has no video to leave half written): the
    // report, the trajectory and the stats of the frames so far are written. To a file, it
    // leaves no partial video, and no trajectory or stats.
    const bool to_window = video::IsWindowTarget(a->out);
    o.cancel_ends_normally = to_window || a->out == "null";

    // A video or a PNG folder is written under a temporary name and renamed when complete.
    std::unique_ptr<PendingOutput> pending;
    if (to_file) {
      pending = std::make_unique<PendingOutput>(a->out);
      o.sink = pending->sink_target();
    } else {
      o.sink = a->out;
    }
    o.recording = &recording;
    recordings::RecordingSource source(recording, replay);
    const map::Map map = LoadSessionMap(a->map_dir, a->session.room);
    o.frame_camera = RecordingTrackingCamera(map.camera, recording.camera);
    if (o.scene_file.empty() && !a->session.no_figure) o.first_view = FirstRunFigure(map, a->map_dir);
    // The scene's lines into a video file's audio track, and played live (--audio-out) when the
    // frames keep real time: --paced.
    o.audio_track = true;
    const audio::OpenedAudioOut sound = a->paced ? OpenAudioOutForScene(a->audio_out, o.scene_file) : audio::OpenedAudioOut{};
    o.sound_out = sound.player.get();
    const SessionResult result = RunSession(source, recording.camera.Size(), map, a->map_dir, o);
    if (pending) pending->Commit();
    std::printf("%s%s%s", PipelineReportText(result.report).c_str(), result.loss_advice.c_str(),
                SoundSummaryText(result.sound).c_str());
    std::printf("%s %s\n", to_window ? "shown in" : "wrote",
                to_window ? result.output.c_str() : a->out.c_str());
  });
}

}  // namespace arview::app
