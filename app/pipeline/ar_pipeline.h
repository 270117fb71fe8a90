#pragma once
// The real-time pipeline: capture → track → animate → render + composite → sink, each on its
// own thread, joined by bounded queues. Live sources keep one waiting frame per stage, the
// newest: a stage that falls behind makes the older one drop (counted), so that after a stall
// every stage jumps to the newest frame instead of draining a backlog. Replays of a recording
// may instead process every frame. Per-stage times and the end-to-end latency (from the frame's
// capture time to its hand-over to the sink) are measured, and each frame's way through the
// stages is logged, so that a late frame can be traced to the stage it waited on.

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "app/pipeline/layered_animator.h"
#include "app/pipeline/stage_stats.h"
#include "recordings/frame_source.h"
#include "recordings/trajectory.h"
#include "video/sinks.h"
#include "tracker/loss_diagnosis.h"
#include "tracker/tracker.h"

namespace arview::app {

using Clock = std::chrono::steady_clock;

// What the render stage gets for one frame.
struct FrameToCompose {
  const recordings::Frame* frame = nullptr;
  const tracker::FrameResult* track = nullptr;
  std::vector<const anim::AnimatorFrame*> animations;  // one per character (none: no character)
  const tracker::LossDiagnosis* loss = nullptr;  // a lost frame's cause (PipelineOptions::diagnoser)
  const CharacterDialogue* dialogue = nullptr;    // the first character's, for the HUD (render thread)
};

class FrameCompositor {
 public:
  virtual ~FrameCompositor() = default;
  // Called once on the render thread before the first frame (e.g. to bind a GL context).
  virtual void BindToThread() {}
  // Called on the render thread after the last frame, however it ends (e.g. to release the context
  // for the thread that destroys it).
  virtual void UnbindFromThread() {}
  // The output picture: the video frame, with the character drawn over it when tracked.
  virtual cv::Mat Compose(const FrameToCompose& input) = 0;
  // Drawing over the composed picture that can wait for the sink's thread (the HUD), called on
  // the render thread right after Compose: what it returns holds copies of what it draws, and
  // runs on the sink's thread before the frame is written. The render stage limits the frame
  // rate on a CPU renderer, and ~1 ms of drawing text and circles need not hold it up. Empty:
  // nothing to draw.
  virtual std::function<void(cv::Mat&)> DeferredOverlay(const FrameToCompose& /*input*/) { return {}; }
};

struct FrameLog;

struct PipelineOptions {
  // Live sources: a slower stage makes the older waiting frame drop, and each queue holds one
  // frame (the freshest). Replays: every frame, through queues of `queue_capacity`.
  bool drop_frames = false;
  size_t queue_capacity = 2;  // at least 1 (PipelineOptions::Check)
  // Live sources: a source that fails while running (a camera unplugged or stalled) ends the
  // run like the end of the stream, and PipelineReport::source_fault says why; the outputs so
  // far are complete. Otherwise its error is rethrown.
  bool end_on_source_fault = false;
  // Live sources: called on the capture thread with one line when the source's frame rate falls
  // well below the rate it kept at first (a camera halving its rate in dim light), and when it
  // recovers.
  std::function<void(const std::string&)> on_source_note;
  // Per-frame records kept in the report: `frames` (about 300 bytes a frame, for the demo's
  // figures) and `trajectory` (80 bytes a localized frame, for the demo's accuracy). `replay` and
  // `run` keep neither (--stats and --trajectory stream them through `on_frame_log` and
  // `on_localized_pose`), so that their memory stays flat (the soak test, docs/reliability.md).
  // What the summaries need is kept in constant memory whatever these say.
  bool keep_frame_logs = true;
  bool keep_trajectory = true;
  // Called on the sink's thread with each frame's record as the frame reaches the sink: --stats
  // writes it to disk then (pipeline_report.h, StatsFileWriter), so that it is not kept.
  std::function<void(const FrameLog&)> on_frame_log;
  // Called on the render thread with each localized frame's raw pose, whether or not the frame
  // then reaches the sink (a frame dropped before the sink was still tracked): --trajectory
  // writes it to disk then (recordings/trajectory.h, TumFileWriter).
  std::function<void(const recordings::StampedPose&)> on_localized_pose;
  // Gives each lost frame its cause (on the track thread, in its `track` time: 1.8 ms a 640x480
  // frame, 3.4 ms a 1920x1080 one): the HUD shows it, the report counts the causes. Null: lost
  // frames have no cause.
  const tracker::LossDiagnoser* diagnoser = nullptr;
  // Called once, on the render thread, with the first localized frame before its characters are
  // animated (inside its `animate` time): a first run without a scene stands its figure in front
  // of that view here (app/session). Null: nothing.
  std::function<void(const tracker::FrameResult&)> on_first_localized;

  // Throws OptionError naming the first bad field (base/option_check.h); RunPipeline
  // calls it first.
  void Check(const OptionNames& names = {}) const;
};

// A frame's way through the pipeline, in milliseconds since its capture.
struct FrameTimeline {
  float arrived = 0;       // the capture thread has it (decoded)
  float track_start = 0, track_end = 0;
  float render_start = 0, render_end = 0;  // animate + render + composite
  float sink_start = 0;
  float output = 0;        // handed to the sink (shown, encoded): the frame's latency
  // Time spent waiting in each queue: what a late frame waited on.
  float WaitBeforeTrack() const { return track_start - arrived; }
  float WaitBeforeRender() const { return render_start - track_end; }
  float WaitBeforeSink() const { return sink_start - render_end; }
};

struct FrameLog {
  int64_t index = 0;        // a recording's frame index; a camera's sequence number
  double timestamp = 0;
  double captured_s = 0;    // capture time, seconds since the pipeline started (< 0: before)
  // The characters' animation time (the frame clock of speech::Utterance: 0 at the first frame
  // composed); < 0: no characters.
  double animation_s = -1;
  FrameTimeline timeline;
  tracker::FrameResult track;
  std::optional<tracker::LossDiagnosis> loss;  // lost, with PipelineOptions::diagnoser: why
  double idle_weight = 0;
  std::optional<double> gaze_error_deg;  // first character: head forward vs direction to the camera
  int actions_triggered = 0;  // first character: distance-triggered actions started (a greeting)
  anim::GazeFrame eyes;       // first character: its eyes on the viewer, blinks (anim/gaze.h; inactive: none)
  anim::FaceFrame face;       // first character: speech on its face (anim/face.h; inactive: none)
  std::string_view saying;    // first character: the line being said (its LayeredAnimator keeps the text), or empty
  std::optional<DialogueFrame> dialogue;  // first character with a dialogue: heard, machine, emotion, expression
};

struct PipelineReport {
  size_t frames_read = 0;
  size_t frames_processed = 0;  // reached the sink
  size_t frames_dropped = 0;    // dropped between stages (a stage was slower than the frame rate)
  size_t frames_localized = 0;  // of the frames processed
  recordings::SourceCounts source;  // what the source discarded (a camera's driver drops, ...)
  // A live source's failure that ended the run (PipelineOptions::end_on_source_fault): the
  // source's one-line message. Empty: the run ended normally.
  std::string source_fault;
  // While running, over the last second or so of output: for the progress line and the window.
  double recent_fps = 0;
  double recent_latency_ms = 0;  // median
  std::optional<Clock::time_point> first_output;  // when the first frame reached the sink
  // When the first localized frame (the characters placed) reached it: with the tracker's worker
  // the first frames are shown with the video alone while it relocalises.
  std::optional<Clock::time_point> first_localized_output;
  double wall_seconds = 0;
  double fps = 0;  // frames processed per wall-clock second
  // CPU time of the whole process (every thread: the stages, llvmpipe's, the encoder's) per
  // frame processed, over the run. On a shared machine this is steadier than the frame rate,
  // and it bounds it: two cores give at most 2000 / cpu_ms_per_frame frames per second.
  double cpu_ms_per_frame = 0;
  // track, animate, render, sink (with the deferred overlay), latency (capture → sink), arrival
  // (capture → the capture thread has it: a camera's decode and buffering)
  std::map<std::string, TimingSummary> stages;
  std::vector<FrameLog> frames;                 // in processing order (PipelineOptions::keep_frame_logs)
  // The summaries of the tracker's time by status ("tracking", "relocalized", "lost") and of the
  // gaze error (first character), in constant memory (base/stats.h: exact for the first 8,192
  // values, then the quantiles within 1%), always.
  std::map<std::string, StreamingSummary> track_ms_by_status;
  StreamingSummary gaze_error_deg;
  size_t gaze_within_20_deg = 0;
  // The first character's eyes (anim/gaze.h), where it has them: frames with gaze, frames with
  // its eyes on the viewer, blinks begun.
  size_t eye_frames = 0, eye_contact_frames = 0;
  long blinks = 0;
  tracker::LossSummary losses;                  // the lost frames' causes (PipelineOptions::diagnoser)
  recordings::Trajectory trajectory;            // raw poses of localized frames
  // The first character's dialogue turns (app/session fills them in after the run, for --stats).
  std::vector<DialogueTurnRecord> dialogue_turns;
};

// Runs until the source ends (or `stop()` returns true, or the sink asks to stop: checked by the
// sink's thread after each frame and at least every 50 ms, which then asks every stage to stop
// between frames; a stopped run drains nothing). The stages and which thread may touch what:
// pipeline_stages.h. `on_frame` runs on the sink's thread after each frame, with no lock held,
// given the sink stage's own report: its counts, first outputs, recent rate and latency and
// summaries so far (frames_read, source_fault, trajectory and stages are filled in once every
// stage has ended). Rethrows on the caller's thread the first error any stage raised, after
// every thread has stopped.
PipelineReport RunPipeline(recordings::FrameSource& source, tracker::Tracker& tracker, std::span<LayeredAnimator* const> animators,
                           FrameCompositor& compositor, video::FrameSink& sink, const PipelineOptions& options,
                           const std::function<void(const PipelineReport&)>& on_frame = {},
                           const std::function<bool()>& stop = {});

// Adds a frame's eyes (FrameLog::eyes) to the report's eye-contact and blink counts
// (pipeline_report.cpp).
void CountEyes(const FrameLog& frame, PipelineReport& report);

// Angle in degrees between the head's forward axis and the direction from the head to the camera
// centre, in map coordinates. Nothing when the character has no look-at chain.
std::optional<double> GazeErrorDeg(const anim::PlacedCharacter& character, std::span<const Eigen::Matrix4d> model,
                                   const Eigen::Vector3d& camera_center_map);

}  // namespace arview::app
