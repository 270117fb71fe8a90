#include "app/pipeline/ar_pipeline.h"

#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

#include <pthread.h>
#include <sys/resource.h>

#include "anim/chains.h"
#include "app/pipeline/bounded_queue.h"

namespace arview::app {

namespace {

struct InFlight {
  recordings::Frame frame;
  Clock::time_point arrival;
  tracker::FrameResult track;
  cv::Mat output;
  std::function<void(cv::Mat&)> overlay;  // FrameCompositor::DeferredOverlay, run by the sink stage
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
// the sink to draw. Returns the frame's log.
FrameLog AnimateAndCompose(InFlight& item, std::span<LayeredAnimator* const> animators, FrameCompositor& compositor,
                           StageStats& stats) {
  FrameLog log;
  log.index = item.frame.index;
  log.timestamp = item.frame.timestamp;
  log.track = item.track;
  const bool localized = item.track.status != tracker::TrackStatus::kLost;
  FrameToCompose compose{&item.frame, &item.track, {}};
  if (!animators.empty()) {
    const Clock::time_point t0 = Clock::now();
    std::optional<Eigen::Vector3d> centre;
    if (localized) centre = item.track.smoothed_center;
    for (LayeredAnimator* animator : animators) {
      compose.animations.push_back(&animator->Update(centre, item.frame.timestamp));
    }
    log.idle_weight = compose.animations.front()->idle_weight();
    log.actions_triggered = compose.animations.front()->triggered;
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
  return log;
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
  BoundedQueue<InFlight> to_track(options.queue_capacity, policy);
  BoundedQueue<InFlight> to_render(options.queue_capacity, policy);
  BoundedQueue<InFlight> to_sink(options.queue_capacity, policy);
  StageStats stats;
  ErrorSlot error;
  PipelineReport report;
  std::mutex report_mutex;
  const Clock::time_point start = Clock::now();
  const double cpu_start = ProcessCpuSeconds();

  // A stop request closes every queue, so that no stage stays blocked pushing to one that
  // stopped popping.
  auto close_all = [&] {
    to_track.Close();
    to_render.Close();
    to_sink.Close();
  };
  auto stopped = [&] {
    if (!(stop && stop())) return false;
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
        while (!error.failed() && !stopped() && !sink.StopRequested()) {
          InFlight item;
          if (!source.Next(item.frame)) break;
          item.arrival = Clock::now();
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
          item->track = tracker.Track(item->frame.image, item->frame.timestamp);
          stats.Record("track", MsSince(t0));
          if (!to_render.Push(std::move(*item))) break;
        }
      },
      to_render));

  std::thread render(guarded(
      [&] {
        NameThisThread("arview-render");
        compositor.BindToThread();
        while (auto item = to_render.Pop()) {
          if (error.failed() || stopped()) break;
          FrameLog log = AnimateAndCompose(*item, animators, compositor, stats);
          const bool localized = item->track.status != tracker::TrackStatus::kLost;
          {
            std::lock_guard lock(report_mutex);
            if (localized) {
              ++report.frames_localized;
              if (options.keep_trajectory) report.trajectory.push_back({item->frame.timestamp, item->track.pose});
            }
            report.briefs.push_back({static_cast<float>(log.track.times.total_ms),
                                     log.gaze_error_deg ? static_cast<float>(*log.gaze_error_deg) : -1.0f,
                                     log.track.status});
            if (options.keep_frame_logs) report.frames.push_back(std::move(log));
          }
          if (!to_sink.Push(std::move(*item))) break;
        }
      },
      to_sink));

  std::thread write(guarded([&] {
    NameThisThread("arview-sink");
    while (auto item = to_sink.Pop()) {
      if (error.failed() || stopped()) break;
      const Clock::time_point t0 = Clock::now();
      if (item->overlay) item->overlay(item->output);
      sink.Write(item->output);
      stats.Record("sink", MsSince(t0));
      stats.Record("latency", MsSince(item->arrival));
      std::lock_guard lock(report_mutex);
      ++report.frames_processed;
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
  FillTotals(start, cpu_start, stats, report);
  return report;
}

}  // namespace arview::app
