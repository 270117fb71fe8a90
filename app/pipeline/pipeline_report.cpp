#include "app/pipeline/pipeline_report.h"

#include <algorithm>
#include <cstdio>
#include <thread>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "speech/visemes.h"

namespace arview::app {

GazeSummary SummarizeGaze(const PipelineReport& report) {
  const Summary s = report.gaze_error_deg.Get();
  GazeSummary g;
  g.frames = s.count;
  g.median_deg = s.median;
  g.max_deg = s.max;
  g.within_20_deg = report.gaze_within_20_deg;
  return g;
}

void CountEyes(const FrameLog& frame, PipelineReport& report) {
  if (!frame.eyes.active) return;
  ++report.eye_frames;
  report.eye_contact_frames += frame.eyes.eyes_on_viewer;
  report.blinks += frame.eyes.blinks_begun;
}

nlohmann::ordered_json TimingJson(const TimingSummary& s) {
  return {{"count", s.count}, {"median_ms", s.median}, {"p95_ms", s.p95}, {"p99_ms", s.p99}, {"mean_ms", s.mean}, {"max_ms", s.max}};
}

namespace {

// --stats's "dialogue_turns": one record per reply (docs/app.md, "--stats").
nlohmann::ordered_json DialogueTurnsJson(const std::vector<DialogueTurnRecord>& turns) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const DialogueTurnRecord& t : turns) {
    nlohmann::ordered_json turn = {{"time_s", t.time_s}, {"heard", t.heard}, {"confidence", t.confidence},
                                   {"machine", t.machine}, {"said", t.said}};
    if (t.heard_end_s >= 0) turn["heard_end_s"] = t.heard_end_s;
    if (t.reply_start_s >= 0) turn["reply_start_s"] = t.reply_start_s;
    if (t.LatencyS() >= 0) turn["latency_ms"] = 1000 * t.LatencyS();
    out.push_back(std::move(turn));
  }
  return out;
}

}  // namespace

nlohmann::ordered_json PipelineSummaryJson(const PipelineReport& r, const std::string& gl_description,
                                           const render::RendererInfo& gl) {
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
  for (const auto& [status, s] : r.track_ms_by_status) by_status[status] = TimingJson(s.Get());
  const GazeSummary g = SummarizeGaze(r);
  j["gaze"] = {{"frames", g.frames},
               {"median_error_deg", g.median_deg},
               {"max_error_deg", g.max_deg},
               {"frames_within_20_deg", g.within_20_deg}};
  if (r.eye_frames > 0)
    j["eyes"] = {{"frames", r.eye_frames},
                 {"on_viewer_frames", r.eye_contact_frames},
                 {"on_viewer_share", static_cast<double>(r.eye_contact_frames) / r.eye_frames},
                 {"blinks", r.blinks}};
  nlohmann::ordered_json& lost_by_cause = j["lost_by_cause"] = nlohmann::ordered_json::object();
  for (const auto& [cause, name] : EnumNames(tracker::LossCause{})) {
    if (r.losses.count(cause) > 0) lost_by_cause[std::string(name)] = r.losses.count(cause);
  }
  if (!r.dialogue_turns.empty()) j["dialogue_turns"] = DialogueTurnsJson(r.dialogue_turns);
  return j;
}

nlohmann::ordered_json FrameLogJson(const FrameLog& f) {
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
  if (f.animation_s >= 0) frame["animation_s"] = f.animation_s;
  if (f.track.status != tracker::TrackStatus::kLost) {
    // The raw centre places the character in the image, the smoothed one drives its animation:
    // `arview eval --smoothed` measures the smoothing's lag from both.
    frame["center"] = {f.track.center[0], f.track.center[1], f.track.center[2]};
    frame["smoothed_center"] = {f.track.smoothed_center[0], f.track.smoothed_center[1], f.track.smoothed_center[2]};
  }
  if (!f.track.room.empty()) frame["room"] = f.track.room;  // a venue's map: where the frame was localized
  if (f.track.align_zncc > 0) frame["align_zncc"] = f.track.align_zncc;  // a whip-pan frame
  if (f.gaze_error_deg) frame["gaze_error_deg"] = *f.gaze_error_deg;
  if (f.actions_triggered) frame["actions_triggered"] = f.actions_triggered;
  if (f.eyes.active) {
    frame["eyes_on_viewer"] = f.eyes.eyes_on_viewer;
    frame["blinking"] = f.eyes.blinking;
    if (f.eyes.blinks_begun) frame["blinks_begun"] = f.eyes.blinks_begun;
  }
  if (f.face.active) {
    // The mouth: its opening as a share of jawOpen (the figure's 14°), the strongest viseme while talking.
    frame["mouth_open"] = f.face.jaw_open;
    if (f.face.viseme >= 0) frame["viseme"] = std::string(ToString(static_cast<speech::Viseme>(f.face.viseme)));
  }
  if (!f.saying.empty()) frame["saying"] = std::string(f.saying);
  if (f.dialogue) {
    const DialogueFrame& d = *f.dialogue;
    nlohmann::ordered_json dialogue = {{"machine", std::string(d.machine)},
                                       {"emotion", std::string(d.emotion)},
                                       {"emotion_intensity", d.emotion_intensity},
                                       {"expression", std::string(d.expression)},
                                       {"expression_weight", d.expression_weight},
                                       {"activation", d.activation},
                                       {"listening", d.listening}};
    if (d.heard_this_frame)
      dialogue["heard"] = {{"text", d.heard_now}, {"confidence", d.heard_confidence}, {"accepted", d.heard_accepted}};
    frame["dialogue"] = std::move(dialogue);
  }
  if (!f.track.reason.empty()) frame["reason"] = f.track.reason;
  if (f.loss) frame["cause"] = {{"kind", ToString(f.loss->cause)}, {"numbers", f.loss->detail}};
  return frame;
}

StatsFileWriter::StatsFileWriter(const std::filesystem::path& file) : file_(file, "--stats") {
  file_.Write("{\n  \"frames\": [");
}

void StatsFileWriter::Add(const FrameLog& frame) {
  file_.Write((frames_ == 0 ? "\n    " : ",\n    ") + FrameLogJson(frame).dump());
  ++frames_;
}

void StatsFileWriter::Finish(const PipelineReport& report, const std::string& gl_description,
                             const render::RendererInfo& gl, const nlohmann::ordered_json& more) {
  nlohmann::ordered_json summary_json = PipelineSummaryJson(report, gl_description, gl);
  if (more.is_object())
    for (const auto& [key, value] : more.items()) summary_json[key] = value;
  // The summary's own braces dropped: its keys follow "frames" in the one object.
  const std::string summary = summary_json.dump(2);
  file_.Write("\n  ]," + summary.substr(1) + "\n");
  file_.Finish();
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
  for (const auto& [status, summary] : r.track_ms_by_status) {
    const TimingSummary s = summary.Get();
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
  if (r.eye_frames) {
    std::snprintf(line, sizeof(line), "eyes: on the viewer in %zu of %zu frames (%.0f%%), %ld blinks\n", r.eye_contact_frames,
                  r.eye_frames, 100.0 * r.eye_contact_frames / r.eye_frames, r.blinks);
    out += line;
  }
  return out + DialogueTurnsText(r.dialogue_turns);
}

std::string DialogueTurnsText(const std::vector<DialogueTurnRecord>& turns) {
  if (turns.empty()) return "";
  std::string out = "dialogue: " + std::to_string(turns.size()) + (turns.size() == 1 ? " turn" : " turns") +
                    " (times on the frame clock)\n";
  for (const DialogueTurnRecord& t : turns) {
    char head[160];
    if (t.heard.empty())
      std::snprintf(head, sizeof head, "  %.2f s: what the viewer did -> %s says ", t.time_s, t.machine.c_str());
    else
      std::snprintf(head, sizeof head, "  %.2f s: heard \"%s\" (confidence %.2f, ended %.2f s) -> %s says ", t.time_s,
                    t.heard.c_str(), t.confidence, t.heard_end_s, t.machine.c_str());
    char tail[96];
    if (t.reply_start_s < 0)
      std::snprintf(tail, sizeof tail, ", not said before the end");
    else if (t.LatencyS() >= 0)
      std::snprintf(tail, sizeof tail, ", from %.2f s: %.0f ms after the words", t.reply_start_s, 1000 * t.LatencyS());
    else
      std::snprintf(tail, sizeof tail, ", from %.2f s", t.reply_start_s);
    out += head + ("\"" + t.said + "\"") + tail + "\n";
  }
  return out;
}

std::string LossAdviceText(const PipelineReport& report, const std::string& map_folder) {
  std::string out;
  const std::vector<std::string> lines = report.losses.Advice(map_folder);
  for (size_t i = 0; i < lines.size(); ++i) out += (i == 0 ? "" : "  ") + lines[i] + "\n";
  return out;
}

}  // namespace arview::app
