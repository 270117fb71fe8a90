#include "app/pipeline/pipeline_stages.h"

#include <cstdio>

#include <pthread.h>

#include "base/stats.h"

namespace arview::app {

void RunStop::Add(std::stop_source stage) {
  std::lock_guard lock(mutex_);
  if (requested_) stage.request_stop();
  stages_.push_back(std::move(stage));
}

void RunStop::Request() {
  std::lock_guard lock(mutex_);
  requested_ = true;
  for (std::stop_source& stage : stages_) stage.request_stop();
}

void RunStop::Fail(std::exception_ptr error) {
  {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = std::move(error);
  }
  Request();
}

bool RunStop::failed() const {
  std::lock_guard lock(mutex_);
  return error_ != nullptr;
}

void RunStop::RethrowIfFailed() const {
  std::lock_guard lock(mutex_);
  if (error_) std::rethrow_exception(error_);
}

void NameThisThread(const char* name) { pthread_setname_np(pthread_self(), name); }

// Over the last two seconds, against the best rate the source kept since its third second (a
// camera settles its exposure first). Falling below 60 % of it is noted once, and so is coming
// back above 85 %.
std::optional<std::string> SourceRateWatch::Add(Clock::time_point captured) {
  if (!first_) first_ = captured;
  recent_.Add(captured);
  if (captured - *first_ < std::chrono::seconds(3) || recent_.size() < 3) return std::nullopt;
  const double rate = recent_.PerSecond();
  best_ = std::max(best_, rate);
  char line[200];
  if (!slow_ && rate < 0.6 * best_) {
    slow_ = true;
    std::snprintf(line, sizeof line,
                  "frames arrive at %.1f per second, down from %.1f (auto exposure in dim light? try --exposure "
                  "lock, or more light; or a busy USB bus)", rate, best_);
    return std::string(line);
  }
  if (slow_ && rate > 0.85 * best_) {
    slow_ = false;
    std::snprintf(line, sizeof line, "frames arrive at %.1f per second again", rate);
    return std::string(line);
  }
  return std::nullopt;
}

CaptureStage::CaptureStage(recordings::FrameSource& source, const PipelineOptions& options, Clock::time_point start,
                           FrameQueue& out)
    : source_(source), options_(options), start_(start), out_(out) {}

void CaptureStage::Run(std::stop_token stop) {
  const std::stop_callback unblock(stop, [this] { out_.Close(); });
  while (!stop.stop_requested()) {
    InFlight item;
    try {
      if (!source_.Next(item.frame)) break;
    } catch (const recordings::SourceError& e) {
      if (!options_.end_on_source_fault) throw;
      source_fault_ = e.what();
      break;
    }
    const Clock::time_point arrival = Clock::now();
    item.captured = item.frame.capture_time == Clock::time_point{} ? arrival : item.frame.capture_time;
    item.log.index = item.frame.index;
    item.log.timestamp = item.frame.timestamp;
    item.log.captured_s = std::chrono::duration<double>(item.captured - start_).count();
    item.log.timeline.arrived = item.MsSinceCapture();
    stats_.Record("arrival", item.log.timeline.arrived);
    if (options_.on_source_note) {
      if (const auto note = rate_.Add(item.captured)) options_.on_source_note(source_.Name() + ": " + *note);
    }
    ++frames_read_;
    if (!out_.Push(std::move(item))) break;
  }
  out_.Close();
}

TrackStage::TrackStage(tracker::Tracker& tracker, const tracker::LossDiagnoser* diagnoser, FrameQueue& in,
                       FrameQueue& out)
    : tracker_(tracker), diagnoser_(diagnoser), in_(in), out_(out) {}

void TrackStage::Run(std::stop_token stop) {
  const std::stop_callback unblock(stop, [this] {
    in_.Close();
    out_.Close();
  });
  while (auto item = in_.Pop()) {
    if (stop.stop_requested()) break;
    item->log.timeline.track_start = item->MsSinceCapture();
    {
      const ScopedStageTimer timer(stats_, "track");
      item->track = tracker_.Track(item->frame.image, item->frame.timestamp);
      if (diagnoser_ && item->track.status == tracker::TrackStatus::kLost) {
        item->log.loss = diagnoser_->Diagnose(item->frame.image, item->track);
      }
    }
    item->log.timeline.track_end = item->MsSinceCapture();
    if (!out_.Push(std::move(*item))) break;
  }
  out_.Close();
}

RenderStage::RenderStage(std::span<LayeredAnimator* const> animators, FrameCompositor& compositor,
                         const PipelineOptions& options, FrameQueue& in, FrameQueue& out)
    : animators_(animators),
      compositor_(compositor),
      keep_trajectory_(options.keep_trajectory),
      on_first_localized_(options.on_first_localized),
      on_localized_pose_(options.on_localized_pose),
      in_(in),
      out_(out) {}

void RenderStage::Run(std::stop_token stop) {
  const std::stop_callback unblock(stop, [this] {
    in_.Close();
    out_.Close();
  });
  compositor_.BindToThread();
  // The context is released for the thread that destroys it however the loop ends.
  struct Unbind {
    FrameCompositor& compositor;
    ~Unbind() { compositor.UnbindFromThread(); }
  } unbind{compositor_};
  while (auto item = in_.Pop()) {
    if (stop.stop_requested()) break;
    item->log.timeline.render_start = item->MsSinceCapture();
    AnimateAndCompose(*item);
    item->log.timeline.render_end = item->MsSinceCapture();
    // The pose is kept whether or not the frame is shown: a frame dropped before the sink was
    // still tracked.
    if (item->track.status != tracker::TrackStatus::kLost) {
      const recordings::StampedPose pose{item->frame.timestamp, item->track.pose};
      if (keep_trajectory_) trajectory_.push_back(pose);
      if (on_localized_pose_) on_localized_pose_(pose);
    }
    if (!out_.Push(std::move(*item))) break;
  }
  out_.Close();
}

// The characters animated (from the smoothed camera centre, or nothing when the frame was lost),
// composed over the video, and the overlay kept for the sink to draw; the frame's log gets what
// was animated. The animation's clock starts at the first frame composed (`first_timestamp_`,
// set then): a camera stamps its frames with the time since the machine started and an imported
// dataset with the Unix time, and the idle layers build their motion from time 0 up to the
// first time they are asked for (7 h of uptime cost the first live frame 1 s; a Unix time would
// have taken hours).
void RenderStage::AnimateAndCompose(InFlight& item) {
  FrameLog& log = item.log;
  log.track = item.track;
  const bool localized = item.track.status != tracker::TrackStatus::kLost;
  FrameToCompose compose{&item.frame, &item.track, {}, log.loss ? &*log.loss : nullptr};
  if (!animators_.empty()) {
    const ScopedStageTimer timer(stats_, "animate");
    if (localized && !localized_before_) {
      localized_before_ = true;
      if (on_first_localized_) on_first_localized_(item.track);
    }
    std::optional<Eigen::Vector3d> centre, axis;
    if (localized) {
      centre = item.track.smoothed_center;
      axis = item.track.pose.CameraToWorldRotation() * Eigen::Vector3d::UnitZ();  // the camera looks along +z
    }
    if (!first_timestamp_) first_timestamp_ = item.frame.timestamp;
    const double animation_time = item.frame.timestamp - *first_timestamp_;
    log.animation_s = animation_time;
    for (LayeredAnimator* animator : animators_) {
      compose.animations.push_back(&animator->Update(centre, animation_time, axis));
    }
    log.idle_weight = compose.animations.front()->idle_weight();
    log.actions_triggered = compose.animations.front()->triggered;
    log.eyes = compose.animations.front()->gaze;
    log.face = compose.animations.front()->face;
    log.saying = animators_.front()->saying();
    if (const CharacterDialogue* dialogue = animators_.front()->dialogue()) {
      log.dialogue = dialogue->frame();
      compose.dialogue = dialogue;
    }
    if (localized) {
      log.gaze_error_deg = GazeErrorDeg(animators_.front()->character(), compose.animations.front()->model,
                                        item.track.center);
    }
  }
  const ScopedStageTimer timer(stats_, "render");
  item.output = compositor_.Compose(compose);
  item.overlay = compositor_.DeferredOverlay(compose);
}

void SinkStage::RecentOutput::Add(Clock::time_point at, double latency_ms) {
  rate_.Add(at);
  latencies_.push_back(latency_ms);
  while (latencies_.size() > rate_.size()) latencies_.pop_front();  // the same window
}

double SinkStage::RecentOutput::MedianLatencyMs() const {
  const std::vector<double> latencies(latencies_.begin(), latencies_.end());
  return latencies.empty() ? 0 : Median(latencies);
}

SinkStage::SinkStage(video::FrameSink& sink, const recordings::FrameSource& source, const PipelineOptions& options,
                     const std::function<void(const PipelineReport&)>& on_frame, const std::function<bool()>& stop,
                     RunStop& run, StageQueues& queues)
    : sink_(sink),
      source_(source),
      options_(options),
      on_frame_(on_frame),
      outside_stop_(stop),
      run_(run),
      queues_(queues) {}

// The caller's stop (Ctrl-C) or the sink's (Esc in the window) stops the whole run.
bool SinkStage::StopAskedFromOutside() {
  if (!(outside_stop_ && outside_stop_()) && !sink_.StopRequested()) return false;
  run_.Request();
  return true;
}

void SinkStage::Run(std::stop_token stop) {
  const std::stop_callback unblock(stop, [this] { queues_.to_sink.Close(); });
  for (;;) {
    bool timed_out = false;
    // Not a plain Pop: the window's events (Esc, an uncovered window) and a stop request are
    // seen even while no frame comes.
    std::optional<InFlight> item = queues_.to_sink.PopFor(std::chrono::milliseconds(50), timed_out);
    if (timed_out) {
      sink_.PumpEvents();
      if (StopAskedFromOutside()) break;
      continue;
    }
    if (!item || stop.stop_requested() || StopAskedFromOutside()) break;
    Write(*item);
  }
}

void SinkStage::Write(InFlight& item) {
  item.log.timeline.sink_start = item.MsSinceCapture();
  {
    const ScopedStageTimer timer(stats_, "sink");
    if (item.overlay) item.overlay(item.output);
    sink_.Write(item.output);
  }
  const Clock::time_point written = Clock::now();
  FrameLog& log = item.log;
  log.timeline.output = item.MsSinceCapture();
  stats_.Record("latency", log.timeline.output);
  recent_.Add(written, log.timeline.output);
  if (options_.on_frame_log) options_.on_frame_log(log);
  Count(std::move(log), written);
  // The sink's own report, which no other thread touches: no lock is held, nothing is copied.
  if (on_frame_) on_frame_(report_);
}

void SinkStage::Count(FrameLog&& log, Clock::time_point written) {
  const bool localized = log.track.status != tracker::TrackStatus::kLost;
  ++report_.frames_processed;
  if (localized) ++report_.frames_localized;
  if (log.loss) report_.losses.Add(*log.loss);
  if (!report_.first_output) report_.first_output = written;
  if (!report_.first_localized_output && localized) report_.first_localized_output = written;
  report_.frames_dropped = queues_.Dropped();
  report_.source = source_.Counts();
  report_.recent_fps = recent_.Fps();
  report_.recent_latency_ms = recent_.MedianLatencyMs();
  report_.track_ms_by_status[ToString(log.track.status)].Add(log.track.times.total_ms);
  if (log.gaze_error_deg) {
    report_.gaze_error_deg.Add(*log.gaze_error_deg);
    report_.gaze_within_20_deg += *log.gaze_error_deg <= 20.0;
  }
  CountEyes(log, report_);
  if (options_.keep_frame_logs) report_.frames.push_back(std::move(log));
}

}  // namespace arview::app
