#include "app/pipeline/pipeline_report.h"

#include <algorithm>
#include <cstdio>
#include <thread>

#include <nlohmann/json.hpp>

namespace arview::app {

GazeSummary SummarizeGaze(const PipelineReport& report) {
  // From the full per-frame logs when they were kept (exact), else from the briefs.
  std::vector<double> errors;
  for (const FrameLog& f : report.frames) {
    if (f.gaze_error_deg) errors.push_back(*f.gaze_error_deg);
  }
  if (report.frames.empty())
    for (const FrameBrief& f : report.briefs)
      if (f.gaze_error_deg >= 0) errors.push_back(f.gaze_error_deg);
  GazeSummary g;
  g.frames = errors.size();
  if (errors.empty()) return g;
  const Summary s = Summarize(errors);
  g.median_deg = s.median;
  g.max_deg = s.max;
  g.within_20_deg = std::count_if(errors.begin(), errors.end(), [](double e) { return e <= 20.0; });
  return g;
}

namespace {

}  // namespace

nlohmann::ordered_json TimingJson(const TimingSummary& s) {
  return {{"count", s.count}, {"median_ms", s.median}, {"p95_ms", s.p95}, {"p99_ms", s.p99}, {"mean_ms", s.mean}, {"max_ms", s.max}};
}

namespace {

std::map<std::string, TimingSummary> TrackTimesByStatus(const PipelineReport& report) {
  std::map<std::string, std::vector<double>> samples;
  for (const FrameLog& f : report.frames) samples[ToString(f.track.status)].push_back(f.track.times.total_ms);
  if (report.frames.empty())
    for (const FrameBrief& f : report.briefs) samples[ToString(f.status)].push_back(f.track_ms);
  std::map<std::string, TimingSummary> out;
  for (auto& [status, v] : samples) out[status] = Summarize(v);
  return out;
}

}  // namespace

std::string PipelineReportJson(const PipelineReport& r, const std::string& gl_description, const render::RendererInfo& gl) {
  nlohmann::ordered_json j;
  j["frames_read"] = r.frames_read;
  j["frames_processed"] = r.frames_processed;
  j["frames_dropped"] = r.frames_dropped;
  j["frames_localized"] = r.frames_localized;
  j["source"] = {{"driver_dropped", r.source.driver_dropped},
                 {"corrupt_skipped", r.source.corrupt_skipped},
                 {"stale_skipped", r.source.stale_skipped}};
  if (!r.source_fault.empty()) j["source_fault"] = r.source_fault;
  j["wall_seconds"] = r.wall_seconds;
  j["frames_per_second"] = r.fps;
  j["cpu_ms_per_frame"] = r.cpu_ms_per_frame;
  j["renderer"] = gl_description;
  j["gl"] = {{"backend", ToString(gl.backend)}, {"device", gl.device},   {"vendor", gl.vendor},
             {"renderer", gl.renderer},         {"version", gl.version}, {"software", gl.software},
             {"llvmpipe_threads", gl.threads}};
  nlohmann::ordered_json& stages = j["stages"] = nlohmann::ordered_json::object();
  for (const auto& [stage, s] : r.stages) stages[stage] = TimingJson(s);
  nlohmann::ordered_json& by_status = j["tracker_time_by_status"] = nlohmann::ordered_json::object();
  for (const auto& [status, s] : TrackTimesByStatus(r)) by_status[status] = TimingJson(s);
  const GazeSummary g = SummarizeGaze(r);
  j["gaze"] = {{"frames", g.frames},
               {"median_error_deg", g.median_deg},
               {"max_error_deg", g.max_deg},
               {"frames_within_20_deg", g.within_20_deg}};
  nlohmann::ordered_json& frames = j["frames"] = nlohmann::ordered_json::array();
  for (const FrameLog& f : r.frames) {
    const FrameTimeline& t = f.timeline;
    nlohmann::ordered_json frame = {{"index", f.index},
                                    {"timestamp", f.timestamp},
                                    {"captured_s", f.captured_s},
                                    {"latency_ms", t.output},
                                    {"timeline_ms", {{"arrived", t.arrived},
                                                     {"track_start", t.track_start},
                                                     {"track_end", t.track_end},
                                                     {"render_start", t.render_start},
                                                     {"render_end", t.render_end},
                                                     {"sink_start", t.sink_start},
                                                     {"output", t.output}}},
                                    {"waited_ms", {{"before_track", t.WaitBeforeTrack()},
                                                   {"before_render", t.WaitBeforeRender()},
                                                   {"before_sink", t.WaitBeforeSink()}}},
                                    {"status", ToString(f.track.status)},
                                    {"inliers", f.track.inliers},
                                    {"rms_px", f.track.rms_px},
                                    {"track_ms", f.track.times.total_ms},
                                    {"idle_weight", f.idle_weight}};
    if (f.track.align_zncc > 0) frame["align_zncc"] = f.track.align_zncc;  // a whip-pan frame
    if (f.gaze_error_deg) frame["gaze_error_deg"] = *f.gaze_error_deg;
    if (f.actions_triggered) frame["actions_triggered"] = f.actions_triggered;
    if (!f.track.reason.empty()) frame["reason"] = f.track.reason;
    frames.push_back(std::move(frame));
  }
  return j.dump(2) + "\n";
}

std::string PipelineReportText(const PipelineReport& r) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line), "frames: %zu read, %zu processed, %zu dropped, %zu localized (%.1f%%)\n",
                r.frames_read, r.frames_processed, r.frames_dropped, r.frames_localized,
                r.frames_processed ? 100.0 * r.frames_localized / r.frames_processed : 0.0);
  out += line;
  if (r.source.driver_dropped || r.source.corrupt_skipped || r.source.stale_skipped) {
    std::snprintf(line, sizeof(line), "camera: %lld dropped by the driver, %lld corrupt, %lld stale (a newer frame was ready)\n",
                  static_cast<long long>(r.source.driver_dropped), static_cast<long long>(r.source.corrupt_skipped),
                  static_cast<long long>(r.source.stale_skipped));
    out += line;
  }
  std::snprintf(line, sizeof(line), "throughput: %.1f frames per second (%.2f s wall clock)\n", r.fps, r.wall_seconds);
  out += line;
  if (const auto latency = r.stages.find("latency"); latency != r.stages.end()) {
    const TimingSummary& l = latency->second;
    std::snprintf(line, sizeof(line), "latency, capture to output: median %.1f ms, p99 %.1f ms, max %.1f ms\n", l.median,
                  l.p99, l.max);
    out += line;
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  std::snprintf(line, sizeof(line), "process CPU: %.1f ms per frame, all threads (%u cores: at most %.0f frames per second)\n",
                r.cpu_ms_per_frame, cores, r.cpu_ms_per_frame > 0 ? 1000.0 * cores / r.cpu_ms_per_frame : 0.0);
  out += line;
  out += "stage          median ms   p95 ms\n";
  for (const auto& [stage, s] : r.stages) {
    std::snprintf(line, sizeof(line), "%-14s %9.2f %8.2f\n", stage.c_str(), s.median, s.p95);
    out += line;
  }
  for (const auto& [status, s] : TrackTimesByStatus(r)) {
    std::snprintf(line, sizeof(line), "tracker, %-12s %5zu frames, median %.2f ms, p95 %.2f ms\n", status.c_str(), s.count,
                  s.median, s.p95);
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
