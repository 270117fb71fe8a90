#include "app/pipeline/ar_pipeline.h"

#include <cmath>

#include <sys/resource.h>

#include "anim/chains.h"
#include "app/pipeline/pipeline_stages.h"

namespace arview::app {

namespace {

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

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

// The stages' timings, each stage's own, in one map (no two stages record the same name).
std::map<std::string, TimingSummary> StageSummaries(std::initializer_list<const StageStats*> stages) {
  std::map<std::string, TimingSummary> all;
  for (const StageStats* stats : stages) all.merge(stats->Summaries());
  return all;
}

// The run's wall time, frame rate and CPU per frame.
void FillTotals(Clock::time_point start, double cpu_start, PipelineReport& report) {
  report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  report.fps = report.wall_seconds > 0 ? report.frames_processed / report.wall_seconds : 0;
  if (report.frames_processed > 0) report.cpu_ms_per_frame = 1e3 * (ProcessCpuSeconds() - cpu_start) / report.frames_processed;
}

}  // namespace

void PipelineOptions::Check(const OptionNames& names) const {
  RequireOption(queue_capacity >= 1, names("queue_capacity"), "at least 1", queue_capacity);
}

PipelineReport RunPipeline(recordings::FrameSource& source, tracker::Tracker& tracker, std::span<LayeredAnimator* const> animators,
                           FrameCompositor& compositor, video::FrameSink& sink, const PipelineOptions& options,
                           const std::function<void(const PipelineReport&)>& on_frame,
                           const std::function<bool()>& stop) {
  options.Check(OptionNames().Nested("pipeline"));
  const OverflowPolicy policy = options.drop_frames ? OverflowPolicy::kDropOldest : OverflowPolicy::kBlock;
  // Live: one waiting frame per stage, so that no stage ever starts on a frame older than the
  // newest one waiting.
  StageQueues queues(options.drop_frames ? 1 : options.queue_capacity, policy);
  RunStop run;
  const Clock::time_point start = Clock::now();
  const double cpu_start = ProcessCpuSeconds();

  StageThread<CaptureStage> capture("arview-capture", run, source, options, start, queues.to_track);
  StageThread<TrackStage> track("arview-track", run, tracker, options.diagnoser, queues.to_track, queues.to_render);
  StageThread<RenderStage> render("arview-render", run, animators, compositor, options,
                                  queues.to_render, queues.to_sink);
  StageThread<SinkStage> write("arview-sink", run, sink, source, options, on_frame, stop, run, queues);
  capture.Start();
  track.Start();
  render.Start();
  write.Start();
  capture.Join();
  track.Join();
  render.Join();
  write.Join();
  if (!run.failed()) sink.Close();
  run.RethrowIfFailed();

  PipelineReport report = write.stage().TakeReport();
  report.frames_read = capture.stage().frames_read();
  report.source_fault = capture.stage().source_fault();
  report.trajectory = render.stage().TakeTrajectory();
  report.frames_dropped = queues.Dropped();
  report.source = source.Counts();
  report.stages = StageSummaries({&capture.stage().stats(), &track.stage().stats(), &render.stage().stats(),
                                  &write.stage().stats()});
  FillTotals(start, cpu_start, report);
  return report;
}

}  // namespace arview::app
