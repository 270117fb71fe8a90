#pragma once
// The four stages of the real-time pipeline (ar_pipeline.h): capture, track, render, sink. Each
// is a class that owns its data and runs on a named thread of its own, in stella_vslam's module
// shape (`run()`, `async_terminate()`, `is_terminated()`) with C++20's std::jthread and
// std::stop_token: StageThread<Stage> starts it, asks it to stop and joins it. RunPipeline is
// their one owner: it makes the queues, starts the four, joins them and puts the report together
// from what each kept.
//
// Which thread may touch what:
//   - A stage's Run() and everything the stage owns (its StageStats, its part of the report, the
//     objects it was given: the source for capture, the tracker for track, the animators and the
//     compositor for render, the sink for sink): only that stage's thread, between Start() and
//     the end of Join(). After Join() the owner reads the stage's results (frames_read(),
//     TakeTrajectory(), TakeReport(), stats()); nobody else ever does.
//   - A frame (InFlight) passes from stage to stage only through the BoundedQueues: it belongs
//     to the stage that popped it until it pushes it on. The queues are the stages' only shared
//     data besides RunStop; both are safe from any thread.
//   - StageThread::Start and Join: the owner's thread. RequestStop and IsTerminated: any thread.
//   - No lock is held across a callback: the progress callback (`on_frame`) and
//     PipelineOptions::on_frame_log run on the sink's thread with the sink's own report, which
//     no other thread touches; on_source_note runs on the capture thread.
//   - Exceptions: a stage's first exception is kept by RunStop and stops the run; the owner
//     rethrows it once every stage has been joined.

#include <atomic>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <stop_token>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "app/pipeline/ar_pipeline.h"
#include "app/pipeline/bounded_queue.h"
#include "app/pipeline/recent_rate.h"

namespace arview::app {

// One frame on its way through the stages.
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

using FrameQueue = BoundedQueue<InFlight>;

// The three queues between the four stages.
struct StageQueues {
  StageQueues(size_t capacity, OverflowPolicy policy)
      : to_track(capacity, policy), to_render(capacity, policy), to_sink(capacity, policy) {}
  size_t Dropped() const { return to_track.Dropped() + to_render.Dropped() + to_sink.Dropped(); }

  FrameQueue to_track, to_render, to_sink;
};

// The one stop of a run, from any thread: asked by the sink (the caller's stop, Esc in the
// window) or by a stage's exception, it asks every started stage's thread to stop; each stage
// then closes its queues (a std::stop_callback), so that none stays blocked on one.
class RunStop {
 public:
  // A started stage's stop; asked at once when the run has stopped already.
  void Add(std::stop_source stage);
  void Request();
  // Keeps the first error and stops the run.
  void Fail(std::exception_ptr error);
  bool failed() const;
  // The owner's thread, after every stage was joined.
  void RethrowIfFailed() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::stop_source> stages_;
  bool requested_ = false;
  std::exception_ptr error_;
};

// Stage threads carry their names, so that top -H, perf and gdb tell them apart (at most 15
// characters: the kernel's limit).
void NameThisThread(const char* name);

// A stage on a thread of its own. `Stage` has `void Run(std::stop_token)`, which returns when
// its input ends or a stop is asked, and closes its output queue then.
template <typename Stage>
class StageThread {
 public:
  template <typename... Args>
  StageThread(const char* name, RunStop& run, Args&&... stage_args)
      : name_(name), run_(run), stage_(std::forward<Args>(stage_args)...) {}
  StageThread(const StageThread&) = delete;
  StageThread& operator=(const StageThread&) = delete;

  void Start() {
    thread_ = std::jthread([this](std::stop_token stop) {
      NameThisThread(name_);
      try {
        stage_.Run(stop);
      } catch (...) {
        run_.Fail(std::current_exception());
      }
      terminated_ = true;
    });
    run_.Add(thread_.get_stop_source());
  }
  // async_terminate: the stage stops between frames, its queues closed.
  void RequestStop() { thread_.request_stop(); }
  bool IsTerminated() const { return terminated_; }
  void Join() {
    if (thread_.joinable()) thread_.join();
  }
  // The owner's thread, after Join().
  Stage& stage() { return stage_; }

 private:
  const char* name_;
  RunStop& run_;
  Stage stage_;
  std::atomic<bool> terminated_{false};
  std::jthread thread_;  // last: stopped and joined before the stage it runs is destroyed
};

// Watches the rate at which a source captures frames (PipelineOptions::on_source_note).
class SourceRateWatch {
 public:
  std::optional<std::string> Add(Clock::time_point captured);

 private:
  std::optional<Clock::time_point> first_;
  RecentRate recent_{std::chrono::seconds(2)};
  double best_ = 0;
  bool slow_ = false;
};

// `arview-capture`: reads the source, stamps each frame's arrival.
class CaptureStage {
 public:
  CaptureStage(recordings::FrameSource& source, const PipelineOptions& options, Clock::time_point start,
               FrameQueue& out);
  void Run(std::stop_token stop);
  size_t frames_read() const { return frames_read_; }
  const std::string& source_fault() const { return source_fault_; }
  const StageStats& stats() const { return stats_; }

 private:
  recordings::FrameSource& source_;
  const PipelineOptions& options_;
  const Clock::time_point start_;
  FrameQueue& out_;
  SourceRateWatch rate_;
  StageStats stats_;  // "arrival"
  size_t frames_read_ = 0;
  std::string source_fault_;
};

// `arview-track`: the tracker, and a lost frame's cause.
class TrackStage {
 public:
  TrackStage(tracker::Tracker& tracker, const tracker::LossDiagnoser* diagnoser, FrameQueue& in, FrameQueue& out);
  void Run(std::stop_token stop);
  const StageStats& stats() const { return stats_; }

 private:
  tracker::Tracker& tracker_;
  const tracker::LossDiagnoser* diagnoser_;
  FrameQueue& in_;
  FrameQueue& out_;
  StageStats stats_;  // "track"
};

// `arview-render`: the characters animated, composed over the video; the trajectory.
class RenderStage {
 public:
  RenderStage(std::span<LayeredAnimator* const> animators, FrameCompositor& compositor, const PipelineOptions& options,
              FrameQueue& in, FrameQueue& out);
  void Run(std::stop_token stop);
  recordings::Trajectory TakeTrajectory() { return std::move(trajectory_); }
  const StageStats& stats() const { return stats_; }

 private:
  void AnimateAndCompose(InFlight& item);

  std::span<LayeredAnimator* const> animators_;
  FrameCompositor& compositor_;
  const bool keep_trajectory_;
  const std::function<void(const tracker::FrameResult&)> on_first_localized_;  // PipelineOptions'
  const std::function<void(const recordings::StampedPose&)> on_localized_pose_;  // PipelineOptions'
  bool localized_before_ = false;
  FrameQueue& in_;
  FrameQueue& out_;
  // The animation's clock starts at the first frame composed (AnimateAndCompose).
  std::optional<double> first_timestamp_;
  recordings::Trajectory trajectory_;
  StageStats stats_;  // "animate", "render"
};

// `arview-sink`: the deferred overlay, the sink; the latency, the report's counts and summaries,
// the progress callback. Watches the stops from outside the pipeline (the caller's, the window's)
// at least every 50 ms.
class SinkStage {
 public:
  SinkStage(video::FrameSink& sink, const recordings::FrameSource& source, const PipelineOptions& options,
            const std::function<void(const PipelineReport&)>& on_frame, const std::function<bool()>& stop,
            RunStop& run, StageQueues& queues);
  void Run(std::stop_token stop);
  PipelineReport TakeReport() { return std::move(report_); }
  const StageStats& stats() const { return stats_; }

 private:
  bool StopAskedFromOutside();
  void Write(InFlight& item);
  void Count(FrameLog&& log, Clock::time_point written);

  // The output rate and the median latency over the last second or so, for the progress line
  // and the window's title.
  class RecentOutput {
   public:
    void Add(Clock::time_point at, double latency_ms);
    double Fps() const { return rate_.PerSecond(); }
    double MedianLatencyMs() const;

   private:
    RecentRate rate_{std::chrono::seconds(1)};
    std::deque<double> latencies_;
  };

  video::FrameSink& sink_;
  const recordings::FrameSource& source_;
  const PipelineOptions& options_;
  const std::function<void(const PipelineReport&)>& on_frame_;
  const std::function<bool()>& outside_stop_;
  RunStop& run_;
  StageQueues& queues_;
  RecentOutput recent_;
  PipelineReport report_;  // all but frames_read, source_fault, trajectory and stages
  StageStats stats_;       // "sink", "latency"
};

}  // namespace arview::app
