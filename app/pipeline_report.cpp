#include "app/pipeline_report.h"

#include <algorithm>
#include <cstdio>

#include "app/json_writer.h"

namespace arview::app {

GazeSummary SummarizeGaze(const PipelineReport& report) {
  std::vector<double> errors;
  for (const FrameLog& f : report.frames) {
    if (f.gaze_error_deg) errors.push_back(*f.gaze_error_deg);
  }
  GazeSummary g;
  g.frames = errors.size();
  if (errors.empty()) return g;
  const TimingSummary s = Summarize(errors);
  g.median_deg = s.median_ms;
  g.max_deg = s.max_ms;
  g.within_20_deg = std::count_if(errors.begin(), errors.end(), [](double e) { return e <= 20.0; });
  return g;
}

namespace {

void WriteSummary(JsonWriter& w, const std::string& key, const TimingSummary& s) {
  w.BeginObject(key)
      .Value("count", s.count)
      .Value("median_ms", s.median_ms)
      .Value("p95_ms", s.p95_ms)
      .Value("mean_ms", s.mean_ms)
      .Value("max_ms", s.max_ms)
      .EndObject();
}

std::map<std::string, TimingSummary> TrackTimesByStatus(const PipelineReport& report) {
  std::map<std::string, std::vector<double>> samples;
  for (const FrameLog& f : report.frames) samples[tracker::TrackStatusName(f.track.status)].push_back(f.track.times.total_ms);
  std::map<std::string, TimingSummary> out;
  for (auto& [status, v] : samples) out[status] = Summarize(v);
  return out;
}

}  // namespace

std::string PipelineReportJson(const PipelineReport& r, const std::string& gl_description) {
  JsonWriter w;
  w.BeginObject();
  w.Value("frames_read", r.frames_read)
      .Value("frames_processed", r.frames_processed)
      .Value("frames_dropped", r.frames_dropped)
      .Value("frames_localized", r.frames_localized)
      .Value("wall_seconds", r.wall_seconds)
      .Value("frames_per_second", r.fps)
      .Value("renderer", gl_description);
  w.BeginObject("stages");
  for (const auto& [stage, s] : r.stages) WriteSummary(w, stage, s);
  w.EndObject();
  w.BeginObject("tracker_time_by_status");
  for (const auto& [status, s] : TrackTimesByStatus(r)) WriteSummary(w, status, s);
  w.EndObject();
  const GazeSummary g = SummarizeGaze(r);
  w.BeginObject("gaze")
      .Value("frames", g.frames)
      .Value("median_error_deg", g.median_deg)
      .Value("max_error_deg", g.max_deg)
      .Value("frames_within_20_deg", g.within_20_deg)
      .EndObject();
  w.BeginArray("frames");
  for (const FrameLog& f : r.frames) {
    w.BeginObject()
        .Value("index", static_cast<long long>(f.index))
        .Value("timestamp", f.timestamp)
        .Value("status", tracker::TrackStatusName(f.track.status))
        .Value("inliers", f.track.inliers)
        .Value("rms_px", f.track.rms_px)
        .Value("track_ms", f.track.times.total_ms)
        .Value("idle_weight", f.idle_weight);
    if (f.gaze_error_deg) w.Value("gaze_error_deg", *f.gaze_error_deg);
    if (!f.track.reason.empty()) w.Value("reason", f.track.reason);
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
  return w.str() + "\n";
}

std::string PipelineReportText(const PipelineReport& r) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line), "frames: %zu read, %zu processed, %zu dropped, %zu localized (%.1f%%)\n",
                r.frames_read, r.frames_processed, r.frames_dropped, r.frames_localized,
                r.frames_processed ? 100.0 * r.frames_localized / r.frames_processed : 0.0);
  out += line;
  std::snprintf(line, sizeof(line), "throughput: %.1f frames per second (%.2f s wall clock)\n", r.fps, r.wall_seconds);
  out += line;
  out += "stage          median ms   p95 ms\n";
  for (const auto& [stage, s] : r.stages) {
    std::snprintf(line, sizeof(line), "%-14s %9.2f %8.2f\n", stage.c_str(), s.median_ms, s.p95_ms);
    out += line;
  }
  for (const auto& [status, s] : TrackTimesByStatus(r)) {
    std::snprintf(line, sizeof(line), "tracker, %-12s %5zu frames, median %.2f ms, p95 %.2f ms\n", status.c_str(), s.count,
                  s.median_ms, s.p95_ms);
    out += line;
  }
  const GazeSummary g = SummarizeGaze(r);
  if (g.frames) {
    std::snprintf(line, sizeof(line), "gaze: head forward vs camera, median %.1f deg, max %.1f deg, %zu/%zu within 20 deg\n",
                  g.median_deg, g.max_deg, g.within_20_deg, g.frames);
    out += line;
  }
  return out;
}

}  // namespace arview::app
