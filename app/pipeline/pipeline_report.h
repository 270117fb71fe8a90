#pragma once
// stats.json and the console summary of a pipeline run.

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "app/pipeline/ar_pipeline.h"
#include "base/atomic_file.h"
#include "render/offscreen.h"

namespace arview::app {

struct GazeSummary {
  size_t frames = 0;
  double median_deg = 0;
  double max_deg = 0;
  size_t within_20_deg = 0;
};

GazeSummary SummarizeGaze(const PipelineReport& report);

// The timing object of stats.json: {count, median_ms, p95_ms, mean_ms, max_ms}.
nlohmann::ordered_json TimingJson(const TimingSummary& summary);
// stats.json's summary: every key but "frames" (counts, timings, "stages",
// "tracker_time_by_status", "gaze", "renderer"; `gl`: what rendered, its "gl": backend, device,
// vendor, renderer, version, software).
nlohmann::ordered_json PipelineSummaryJson(const PipelineReport& report, const std::string& gl_description,
                                           const render::RendererInfo& gl = {});
// One element of stats.json's "frames": the frame's way through the stages and its tracking.
nlohmann::ordered_json FrameLogJson(const FrameLog& frame);
std::string PipelineReportText(const PipelineReport& report);
// The dialogue's turns for the summary, one line each (heard, confidence, the machine, the reply
// and its latency); PipelineReportText ends with it. Empty without turns.
std::string DialogueTurnsText(const std::vector<DialogueTurnRecord>& turns);
// The lost frames grouped by cause, with advice (tracker/loss_diagnosis.h), one line each after
// "lost N frames:"; empty when none was lost or no cause was given. `map_folder` names map.png.
std::string LossAdviceText(const PipelineReport& report, const std::string& map_folder);

// --stats, written while the session runs, so that a session that runs all day keeps no frame
// in memory. The file is one JSON object, its per-frame part first, one frame a line:
//
//   {
//     "frames": [
//       {"index":0,"timestamp":0.0,...},
//       {"index":1,...}
//     ],
//     "frames_read": 2, ... the summary (PipelineSummaryJson) ...
//   }
//
// While running it is "stats.partial.json" beside the final name (PendingOutput), each frame's
// line flushed to it as the frame reaches the sink; Finish writes the summary after the frames,
// fsyncs and renames it into place. So stats.json is complete or absent: an interrupted run
// whose outputs are dropped (a replay into a video stopped by Ctrl-C, an error) removes the
// partial file, and one killed outright (SIGKILL, power) leaves only the partial file, its
// frames readable line by line and no summary, which says it is not complete. A run whose
// Ctrl-C or SIGTERM is its normal end (`arview run`, a replay into a window or null) and one
// whose camera was unplugged finish it with the summary of the frames they ran.
class StatsFileWriter {
 public:
  // Throws arview::Error naming `file` when it cannot be written (before the session starts).
  explicit StatsFileWriter(const std::filesystem::path& file);
  StatsFileWriter(const StatsFileWriter&) = delete;
  StatsFileWriter& operator=(const StatsFileWriter&) = delete;

  // One frame's line, flushed (to the kernel; Finish fsyncs). From one thread at a time (the
  // pipeline's sink thread).
  void Add(const FrameLog& frame);
  // The summary after the frames; then the file is renamed into place. Throws arview::Error
  // naming the file when a write fails.
  // `more`: keys of the session's own added after the summary's (the sound's, app/session).
  void Finish(const PipelineReport& report, const std::string& gl_description, const render::RendererInfo& gl = {},
              const nlohmann::ordered_json& more = {});
  std::size_t frames() const { return frames_; }

 private:
  StreamedFile file_;
  std::size_t frames_ = 0;
};

}  // namespace arview::app
