#include "app/pipeline/ar_pipeline.h"

#include <atomic>
#include <cmath>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

#include <pthread.h>
#include <sys/resource.h>

#include "anim/chains.h"
#include "app/pipeline/bounded_queue.h"
#include "app/pipeline/recent_rate.h"
#include "base/stats.h"

namespace arview::app {

namespace {

struct InFlight {
  recordings::Frame frame;
  Clock::time_point captured;  // the source's capture time, or the arrival when it has none
  tracker::FrameResult track;
  FrameLog log;  // filled stage by stage, kept by the sink stage
  cv::Mat output;
  std::function<void(cv::Mat&)> overlay;  // FrameCompositor::DeferredOverlay, run by the sink stage

  // Milliseconds from the capture to now, for the frame's timeline.
  float MsSinceCapture() const {
    return static_cast<float>(std::chrono::duration<double, std::milli>(Clock::now() - captured).count());
  }
};

// The output rate and the median latency over the last second or so, for the progress line
// and the window's title.
class RecentOutput {
 public:
  void Add(Clock::time_point at, double latency_ms) {
    rate_.Add(at);
    latencies_.push_back(latency_ms);
    while (latencies_.size() > rate_.size()) latencies_.pop_front();  // the same window
  }
  double Fps() const { return rate_.PerSecond(); }
  double MedianLatencyMs() const {
    const std::vector<double> latencies(latencies_.begin(), latencies_.end());
    return latencies.empty() ? 0 : Median(latencies);
  }

 private:
  RecentRate rate_{std::chrono::seconds(1)};
  std::deque<double> latencies_;
};

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// Stage threads carry their names, so that top -H, perf and gdb tell them apart (at most 15
// characters: the kernel's limit).
void NameThisThread(const char* name) { pthread_setname_np(pthread_self(), name); }

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The first exception any stage throws; the others stop when they see it.
class ErrorSlot {
 public:
  void Set(std::exception_ptr e) {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = e;
    failed_ = true;
  }
  bool failed() const { return failed_; }
  void RethrowIfAny() {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

// Watches the rate at which a source captures frames: over the last two seconds, against the
// best rate it kept since its third second (a camera settles its exposure first). Falling below
// 60 % of it is noted once, and so is coming back above 85 %.
class SourceRateWatch {
 public:
  std::optional<std::string> Add(Clock::time_point captured) {
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

 private:
  std::optional<Clock::time_point> first_;
  RecentRate recent_{std::chrono::seconds(2)};
  double best_ = 0;
  bool slow_ = false;
};

}  // namespace

std::optional<double> GazeErrorDeg(const anim::PlacedCharacter& character, std::span<const Eigen::Matrix4d> model,
                                   const Eigen::Vector3d& camera_center_map) {
  const anim::LookAtChain& chain = character.lookat_chain();
  if (chain.joints.empty()) return std::nullopt;
  const Eigen::Matrix4d to_map = character.placement().ModelToMap();
  const Eigen::Vector3d forward_model = anim::HeadForward(chain, model);
  const Eigen::Vector3d head_model = model[chain.joints.back()].block<3, 1>(0, 3);
  const Eigen::Vector3d forward = (to_map.block<3, 3>(0, 0) * forward_model).normalized();
  const Eigen::Vector3d head = (to_map * head_model.homogeneous()).head<3>();
  const Eigen::Vector3d to_camera = (camera_center_map - head).normalized();
  return std::acos(std::clamp(forward.dot(to_camera), -1.0, 1.0)) * 180.0 / M_PI;
}

namespace {

// The render stage's work on one frame: the characters animated (from the smoothed camera
// centre, or nothing when the frame was lost), composed over the video, and the overlay kept for
// the sink to draw; the frame's log gets what was animated. The animation's clock starts at the
// first frame composed (`first_timestamp`, set then): a camera stamps its frames with the time
// since the machine started and an imported dataset with the Unix time, and the idle layers
// build their motion from time 0 up to the first time they are asked for (7 h of uptime cost
// the first live frame 1 s; a Unix time would have taken hours).
void AnimateAndCompose(InFlight& item, std::span<LayeredAnimator* const> animators, FrameCompositor& compositor,
                       StageStats& stats, std::optional<double>& first_timestamp) {
  FrameLog& log = item.log;
  log.track = item.track;
  const bool localized = item.track.status != tracker::TrackStatus::kLost;
  FrameToCompose compose{&item.frame, &item.track, {}, log.loss ? &*log.loss : nullptr};
  if (!animators.empty()) {
    const Clock::time_point t0 = Clock::now();
    std::optional<Eigen::Vector3d> centre;
    if (localized) centre = item.track.smoothed_center;
    if (!first_timestamp) first_timestamp = item.frame.timestamp;
    const double animation_time = item.frame.timestamp - *first_timestamp;
    for (LayeredAnimator* animator : animators) {
      compose.animations.push_back(&animator->Update(centre, animation_time));
    }
    log.idle_weight = compose.animations.front()->idle_weight();
    log.actions_triggered = compose.animations.front()->triggered;
    log.eyes = compose.animations.front()->gaze;
    if (localized) {
      log.gaze_error_deg = GazeErrorDeg(animators.front()->character(), compose.animations.front()->model,
                                        item.track.center);
    }
    stats.Record("animate", MsSince(t0));
  }
  const Clock::time_point t1 = Clock::now();
  item.output = compositor.Compose(compose);
  item.overlay = compositor.DeferredOverlay(compose);
  stats.Record("render", MsSince(t1));
}

// The run's wall time, frame rate, CPU per frame and stage summaries.
void FillTotals(Clock::time_point start, double cpu_start, const StageStats& stats, PipelineReport& report) {
  report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  report.fps = report.wall_seconds > 0 ? report.frames_processed / report.wall_seconds : 0;
  if (report.frames_processed > 0) report.cpu_ms_per_frame = 1e3 * (ProcessCpuSeconds() - cpu_start) / report.frames_processed;
  report.stages = stats.Summaries();
}

}  // namespace

PipelineReport RunPipeline(recordings::FrameSource& source, tracker::Tracker& tracker, std::span<LayeredAnimator* const> animators,
                           FrameCompositor& compositor, video::FrameSink& sink, const PipelineOptions& options,
                           const std::function<void(const PipelineReport&)>& on_frame,
                           const std::function<bool()>& stop) {
  const OverflowPolicy policy = options.drop_frames ? OverflowPolicy::kDropOldest : OverflowPolicy::kBlock;
  // Live: one waiting frame per stage, so that no stage ever starts on a frame older than the
  // newest one waiting.
  const size_t capacity = options.drop_frames ? 1 : options.queue_capacity;
  BoundedQueue<InFlight> to_track(capacity, policy);
  BoundedQueue<InFlight> to_render(capacity, policy);
  BoundedQueue<InFlight> to_sink(capacity, policy);
  StageStats stats;
  ErrorSlot error;
  PipelineReport report;
  std::mutex report_mutex;
  const Clock::time_point start = Clock::now();
  const double cpu_start = ProcessCpuSeconds();

  // A stop request (the caller's, or the sink's: Esc in the window) closes every queue, so that
  // no stage stays blocked pushing to one that stopped popping.
  auto close_all = [&] {
    to_track.Close();
    to_render.Close();
    to_sink.Close();
  };
  auto stopped = [&] {
    if (!(stop && stop()) && !sink.StopRequested()) return false;
    close_all();
    return true;
  };

  auto guarded = [&](auto&& body, auto&... downstream) {
    return [&, body] {
      try {
        body();
      } catch (...) {
        error.Set(std::current_exception());
        close_all();  // unblock every other stage, upstream ones included
      }
      (downstream.Close(), ...);
    };
  };

  std::thread capture(guarded(
      [&] {
        NameThisThread("arview-capture");
        size_t read = 0;
        SourceRateWatch rate;
        while (!error.failed() && !stopped()) {
          InFlight item;
          try {
            if (!source.Next(item.frame)) break;
          } catch (const recordings::SourceError& e) {
            if (!options.end_on_source_fault) throw;
            std::lock_guard lock(report_mutex);
            report.source_fault = e.what();
            break;
          }
          const Clock::time_point arrival = Clock::now();
          item.captured = item.frame.capture_time == Clock::time_point{} ? arrival : item.frame.capture_time;
          item.log.index = item.frame.index;
          item.log.timestamp = item.frame.timestamp;
          item.log.captured_s = std::chrono::duration<double>(item.captured - start).count();
          item.log.timeline.arrived = item.MsSinceCapture();
          stats.Record("arrival", item.log.timeline.arrived);
          if (options.on_source_note) {
            if (const auto note = rate.Add(item.captured)) options.on_source_note(source.Name() + ": " + *note);
          }
          ++read;
          if (!to_track.Push(std::move(item))) break;
        }
        std::lock_guard lock(report_mutex);
        report.frames_read = read;
      },
      to_track));

  std::thread track(guarded(
      [&] {
        NameThisThread("arview-track");
        while (auto item = to_track.Pop()) {
          if (error.failed() || stopped()) break;
          const Clock::time_point t0 = Clock::now();
          item->log.timeline.track_start = item->MsSinceCapture();
          item->track = tracker.Track(item->frame.image, item->frame.timestamp);
          if (options.diagnoser && item->track.status == tracker::TrackStatus::kLost) {
            item->log.loss = options.diagnoser->Diagnose(item->frame.image, item->track);
          }
          stats.Record("track", MsSince(t0));
          item->log.timeline.track_end = item->MsSinceCapture();
          if (!to_render.Push(std::move(*item))) break;
        }
      },
      to_render));

  std::thread render(guarded(
      [&] {
        NameThisThread("arview-render");
        compositor.BindToThread();
        struct Unbind {
          FrameCompositor& compositor;
          ~Unbind() { compositor.UnbindFromThread(); }
        } unbind{compositor};
        std::optional<double> first_timestamp;
        while (auto item = to_render.Pop()) {
          if (error.failed() || stopped()) break;
          item->log.timeline.render_start = item->MsSinceCapture();
          AnimateAndCompose(*item, animators, compositor, stats, first_timestamp);
          item->log.timeline.render_end = item->MsSinceCapture();
          // The pose is kept whether or not the frame is shown: a frame dropped before the sink
          // was still tracked.
          if (options.keep_trajectory && item->track.status != tracker::TrackStatus::kLost) {
            std::lock_guard lock(report_mutex);
            report.trajectory.push_back({item->frame.timestamp, item->track.pose});
          }
          if (!to_sink.Push(std::move(*item))) break;
        }
      },
      to_sink));

  std::thread write(guarded([&] {
    NameThisThread("arview-sink");
    RecentOutput recent;
    for (;;) {
      bool timed_out = false;
      // Not a plain Pop: the window's events (Esc, an uncovered window) and a stop request are
      // seen even while no frame comes.
      std::optional<InFlight> item = to_sink.PopFor(std::chrono::milliseconds(50), timed_out);
      if (timed_out) {
        sink.PumpEvents();
        if (stopped()) break;
        continue;
      }
      if (!item || error.failed() || stopped()) break;
      const Clock::time_point t0 = Clock::now();
      item->log.timeline.sink_start = item->MsSinceCapture();
      if (item->overlay) item->overlay(item->output);
      sink.Write(item->output);
      const Clock::time_point written = Clock::now();
      stats.Record("sink", MsSince(t0));
      FrameLog& log = item->log;
      log.timeline.output = item->MsSinceCapture();
      stats.Record("latency", log.timeline.output);
      recent.Add(written, log.timeline.output);
      if (options.on_frame_log) options.on_frame_log(log);  // outside the lock: it writes to disk
      std::lock_guard lock(report_mutex);
      ++report.frames_processed;
      if (log.track.status != tracker::TrackStatus::kLost) ++report.frames_localized;
      if (log.loss) report.losses.Add(*log.loss);
      if (!report.first_output) report.first_output = written;
      if (!report.first_localized_output && log.track.status != tracker::TrackStatus::kLost) {
        report.first_localized_output = written;
      }
      report.frames_dropped = to_track.Dropped() + to_render.Dropped() + to_sink.Dropped();
      report.source = source.Counts();
      report.recent_fps = recent.Fps();
      report.recent_latency_ms = recent.MedianLatencyMs();
      report.track_ms_by_status[ToString(log.track.status)].Add(log.track.times.total_ms);
      if (log.gaze_error_deg) {
        report.gaze_error_deg.Add(*log.gaze_error_deg);
        report.gaze_within_20_deg += *log.gaze_error_deg <= 20.0;
      }
      CountEyes(log, report);
      if (options.keep_frame_logs) report.frames.push_back(std::move(log));
      if (on_frame) on_frame(report);
    }
  }));

  capture.join();
  track.join();
  render.join();
  write.join();
  if (!error.failed()) sink.Close();
  error.RethrowIfAny();

  report.frames_dropped = to_track.Dropped() + to_render.Dropped() + to_sink.Dropped();
  report.source = source.Counts();
  FillTotals(start, cpu_start, stats, report);
  return report;
}

}  // namespace arview::app
