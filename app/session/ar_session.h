#pragma once
// One augmented-reality session, shared by `arview replay`, `arview run` and `arview demo`:
// load the map and the scene, build the tracker, the characters' animators and the compositor,
// run the pipeline from a frame source into a sink, and write the trajectory and stats.

#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "app/pipeline/ar_compositor.h"
#include "base/cancellation.h"
#include "app/pipeline/ar_pipeline.h"
#include "app/pipeline/layered_animator.h"
#include "app/session/session_sound.h"
#include "app/session/session_dialogue.h"
#include "anim_authoring/scene.h"
#include "base/geometry.h"
#include "map/map.h"
#include "recordings/frame_source.h"
#include "recordings/recording.h"
#include "speech/utterance.h"

namespace arview::app {

// A first run without a scene (`run`, `replay` without --scene): its character is stood in
// front of the first localized view. Placing is app/placement's, which app/session may not use
// (a layer beside the pipeline, docs/architecture.md), so the command hands both parts down.
struct FirstViewCharacter {
  authoring::Scene scene;  // one character, standing on the map's floor (where `arview place` stands it)
  // The anchor it takes for the first localized view (world → camera), on the render thread,
  // before that frame is animated.
  std::function<Anchor(const calib::Pose& view)> stand_in_front_of;
  // Told where it now stands, the view, and what moving it took (ms), on the render thread.
  std::function<void(const Anchor& anchor, const calib::Pose& view, double milliseconds)> on_placed;
};

struct SessionOptions {
  std::filesystem::path scene_file;          // empty: `first_view`'s character, or none
  std::optional<FirstViewCharacter> first_view;  // used without a scene file; nothing: video + tracking only
  std::string sink = "window";               // video::OpenSink target
  video::WindowPlacement window;             // for a window sink: its output, fullscreen
  double sink_fps = 30;
  std::filesystem::path trajectory_out;      // optional TUM file
  std::filesystem::path stats_out;           // optional stats.json, written as the frames come
  CompositorOptions compositor;
  FadeOptions fade;
  PipelineOptions pipeline;
  tracker::TrackerOptions tracker;
  // The camera the frames come from, which tracks them and which the scene is drawn with: a
  // replay's calibrated camera.yaml where it is not the map's (RecordingTrackingCamera), `run
  // --camera`'s calibration, or the map's camera scaled to the device's size; nothing: the map's
  // camera. The map gives only the world: the scene's placement stays in map units.
  // `recording`: a replay's, which may hold a still-image map's keyframe images
  // (app/session/keyframe_appearance.h, for the cause of each lost frame); null for a live camera.
  std::optional<calib::Camera> frame_camera;
  const recordings::Recording* recording = nullptr;
  long expected_frames = 0;                  // for the progress line (0: unknown)
  // Ctrl-C / SIGTERM: the pipeline stops, nothing is written (no trajectory; the stats written
  // so far are removed) and RunSession throws CancelledError saying so; the caller removes its
  // partial video.
  CancellationToken cancel;
  std::string output_name;                   // what the sink's output is called, for that message
  // Live sessions (`arview run`) end by Ctrl-C: then a cancellation is the normal end, and the
  // outputs are written.
  bool cancel_ends_normally = false;
  bool quiet = false;
  // Called on arview-render when a character starts a line (its 16 kHz samples and its start on
  // the frame clock, speech/utterance.h): for live sound output. Must not block.
  std::function<void(const speech::Utterance&)> on_utterance;
  // Issue 53's sound (app/session/session_sound.h). `sound_out`: the player the lines are played
  // on live (the caller's, kept until RunSession returns; null: no live sound). With one, lines
  // start kLiveSpeechDelay after their cues, so that the sound reaches the player its lead ahead.
  // `audio_track`: a video file sink gets an AAC track with the lines, when the scene has lines or
  // a dialogue (its replies, and what it hears from a WAV: SessionSound::AddHeardAudio).
  audio::ClipPlayer* sound_out = nullptr;
  bool audio_track = false;
  // The first character listens and answers (issue 54): --dialogue, --mic, --audio-in.
  DialogueSessionOptions dialogue;
  // When the command started, for "first frame shown after ..." (default: RunSession's start).
  std::optional<Clock::time_point> command_start;

  // Throws OptionError naming the first bad field, its own or a member's ("tracker.tracking.
  // prefetch_below"); RunSession calls it first, app/cli with its flags' names.
  void Check(const OptionNames& names = {}) const;
};

struct SessionResult {
  PipelineReport report;
  std::string renderer;
  render::RendererInfo renderer_info;
  std::string output;  // the sink's description ("window \"arview\" (MIT-SHM)", a file, ...)
  double seconds_to_first_output = -1;  // from SessionOptions::command_start; < 0: no frame shown
  double seconds_to_first_localized_output = -1;  // the same for the first frame with its characters placed
  // What the start-up took before the first frame was asked for, in seconds: the tracker (its
  // descriptor index) and its warm-up, the characters, the renderer (GL context, PRT).
  // The tracker's start runs beside the renderer's warm-up (a first draw of the characters).
  double tracker_seconds = 0, characters_seconds = 0, renderer_seconds = 0, warmup_seconds = 0;
  // The lost frames by cause with advice (LossAdviceText), for the command's summary.
  std::string loss_advice{};
  // Every line the characters started, in the order they started (speech/utterance.h): for the
  // audio track of a written video.
  std::vector<speech::Utterance> utterances{};
  // Where the lines' sound went (played, heard when, underruns; the video's track).
  SoundReport sound{};
};

// Frames per second of a recording from its median frame interval: 30 for a single frame, 10
// for still-photo datasets (stamped a second apart), so that their videos are watchable.
double MedianFrameRate(const std::vector<recordings::FrameEntry>& frames);

// Whether any of the scene's characters has `lines:` (its session then has sound to play or write).
bool SceneHasLines(const authoring::Scene& scene);

// The camera a recording's frames are tracked with on `map_camera`'s map: the recording's own
// calibration where it is calibrated and differs from the map's camera (another size, or a
// focal length or principal point more than 2% off: tracker::LossThresholds::camera_tolerance);
// nothing (the map's camera) where the recording is uncalibrated (its camera is a guess, the
// map holds the refined one) or is the map's camera (which may be refined from these frames).
std::optional<calib::Camera> RecordingTrackingCamera(const calib::Camera& map_camera, const calib::Camera& recording);

// `source_size` is the size of the source's frames: it must match the frames' camera
// (options.frame_camera, else the map's). `map_name`
// names the map in messages. Throws CancelledError when options.cancel was cancelled.
SessionResult RunSession(recordings::FrameSource& source, cv::Size source_size, const map::Map& map,
                         const std::string& map_name, const SessionOptions& options);

}  // namespace arview::app
