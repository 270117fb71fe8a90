// arview track <recording> --map <map-dir> --out traj.txt [--frames <spec>] [--stats stats.json]
//
// Tracks frames of a recording against a map: a TUM trajectory of the localised frames (the
// recording's timestamps, lost frames omitted), optional per-frame statistics as JSON, and a
// summary on stdout (frames localised, median and 95th percentile time per status).

#include <algorithm>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "app/cli/commands.h"
#include "app/cli/numeric_flags.h"
#include "app/cli/output_flags.h"
#include "base/progress.h"
#include "app/cli/session_flags.h"
#include "app/pipeline/stage_stats.h"
#include "app/session/keyframe_appearance.h"
#include "base/cancellation.h"
#include "base/atomic_file.h"
#include "map/map_file.h"
#include "recordings/frame_source.h"
#include "recordings/recording.h"
#include "recordings/trajectory.h"
#include "tracker/loss_diagnosis.h"
#include "tracker/tracker.h"

namespace arview::app {

namespace {

struct TrackArgs {
  std::string recording;
  std::string map;
  std::string out;
  std::string frames;
  std::string stats;
  std::string solver = "kneip";
  int max_features = tracker::RelocalizerOptions{}.features.max_features;
  double sift_contrast = tracker::RelocalizerOptions{}.features.contrast_threshold;
  int reduced_max_features = tracker::RelocalizerOptions{}.reduced_features.max_features;
  double reduced_sift_contrast = tracker::RelocalizerOptions{}.reduced_features.contrast_threshold;
  double guided_sift_contrast = tracker::TrackingOptions{}.guided_contrast_threshold;
  double ratio = 0.8;
  double ransac_threshold_px = tracker::RelocalizerOptions{}.pose.ransac_threshold_px;
  double inlier_threshold_px = tracker::RelocalizerOptions{}.pose.inlier_threshold_px;
  double tracking_ransac_threshold_px = tracker::TrackingOptions{}.ransac_threshold_px;
  int ransac_iterations = 1000;
  int min_inliers = 12;
  double max_rms_px = 2.5;
  int tracking_min_inliers = 30;
  int replenish_below = 150;
  double fresh_features_after = tracker::TrackingOptions{}.fresh_features_after_s;
  int prefetch_below = tracker::TrackingOptions{}.prefetch_below;
  int prefetch_lag = tracker::TrackingOptions{}.prefetch_lag_frames;
  double guided_radius_px = 10;
  int lk_window = tracker::TrackingOptions{}.lk_window_px;
  int lk_levels = tracker::TrackingOptions{}.lk_pyramid_levels;
  double align_max_seconds = tracker::TrackingOptions{}.align_max_seconds;
  int index_checks = 32;
  unsigned seed = 0;
  int threads = 1;
  double smoothing_min_cutoff = 1.0;
  double smoothing_beta = 0.5;
  int working_size = tracker::TrackerOptions{}.working_long_side;
  int sift_size = tracker::RelocalizerOptions{}.sift_long_side;
  int reloc_sift_size = tracker::RelocalizerOptions{}.reloc_sift_long_side;
};

tracker::TrackerOptions MakeOptions(const TrackArgs& a) {
  tracker::TrackerOptions o;
  try {
    o.relocalization.pose.solver = tracker::ParseMinimalSolver(a.solver);
  } catch (const Error& e) {
    throw CommandError(std::string("--solver: ") + e.what());
  }
  o.relocalization.features.max_features = a.max_features;
  o.relocalization.features.contrast_threshold = a.sift_contrast;
  o.relocalization.reduced_features.max_features = a.reduced_max_features;
  o.relocalization.reduced_features.contrast_threshold = a.reduced_sift_contrast;
  o.relocalization.matching.ratio = a.ratio;
  o.relocalization.pose.ransac_threshold_px = a.ransac_threshold_px;
  o.relocalization.pose.inlier_threshold_px = a.inlier_threshold_px;
  o.tracking.ransac_threshold_px = a.tracking_ransac_threshold_px;
  o.relocalization.pose.ransac_max_iterations = a.ransac_iterations;
  o.relocalization.pose.min_inliers = a.min_inliers;
  o.relocalization.pose.max_rms_px = a.max_rms_px;
  o.relocalization.pose.seed = a.seed;
  o.tracking.min_inliers = a.tracking_min_inliers;
  o.tracking.replenish_below = a.replenish_below;
  o.tracking.fresh_features_after_s = a.fresh_features_after;
  o.tracking.prefetch_below = a.prefetch_below;
  o.tracking.prefetch_lag_frames = a.prefetch_lag;
  o.tracking.guided_radius_px = a.guided_radius_px;
  o.tracking.guided_contrast_threshold = a.guided_sift_contrast;
  o.tracking.lk_window_px = a.lk_window;
  o.tracking.lk_pyramid_levels = a.lk_levels;
  o.tracking.align_max_seconds = a.align_max_seconds;
  o.smoothing.min_cutoff_hz = a.smoothing_min_cutoff;
  o.smoothing.beta = a.smoothing_beta;
  o.index.seed = a.seed;
  o.index.checks = a.index_checks;
  o.working_long_side = a.working_size;
  o.relocalization.sift_long_side = a.sift_size;
  o.relocalization.reloc_sift_long_side = a.reloc_sift_size;
  return o;
}

struct FrameRecord {
  int index = 0;
  double timestamp = 0;
  tracker::FrameResult result;
  std::optional<tracker::LossDiagnosis> loss;  // lost: why (tracker/loss_diagnosis.h)
};

nlohmann::ordered_json FrameJson(const FrameRecord& f) {
  const auto& r = f.result;
  nlohmann::ordered_json j = {{"index", f.index},
                              {"timestamp", f.timestamp},
                              {"status", ToString(r.status)},
                              {"inliers", r.inliers},
                              {"rms_px", r.rms_px},
                              {"rms_gate_px", r.rms_gate_px},
                              {"flow_tracks", r.flow_tracks},
                              {"guided_matches", r.guided_matches},
                              {"prefetched_matches", r.prefetched_matches},
                              {"wide_matches", r.wide_matches},
                              {"fresh_inliers", r.fresh_inliers},
                              {"flow_motion_px", r.flow_motion_px},
                              {"align_zncc", r.align_zncc},
                              {"keypoints", r.keypoints},
                              {"matches", r.matches},
                              {"reason", r.reason}};
  j["ms"] = {{"flow", r.times.flow_ms},       {"extract", r.times.extract_ms}, {"match", r.times.match_ms},
             {"ransac", r.times.ransac_ms},   {"refine", r.times.refine_ms},   {"total", r.times.total_ms},
             {"cpu", r.times.cpu_ms}};
  if (f.loss) j["cause"] = {{"kind", ToString(f.loss->cause)}, {"numbers", f.loss->detail}};
  if (r.status != tracker::TrackStatus::kLost) {
    j["center"] = {r.center[0], r.center[1], r.center[2]};
    j["smoothed_center"] = {r.smoothed_center[0], r.smoothed_center[1], r.smoothed_center[2]};
  }
  return j;
}

// Per status (and "all"): wall time and thread CPU time of Track().
struct StatusSummary {
  TimingSummary wall;
  TimingSummary cpu;
};
using StatusSummaries = std::map<std::string, StatusSummary>;

StatusSummaries SummarizeByStatus(const std::vector<FrameRecord>& frames) {
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> samples;
  for (const auto& f : frames) {
    for (const std::string& key : {ToString(f.result.status), std::string("all")}) {
      samples[key].first.push_back(f.result.times.total_ms);
      samples[key].second.push_back(f.result.times.cpu_ms);
    }
  }
  StatusSummaries out;
  for (auto& [status, ms] : samples) out[status] = {Summarize(ms.first), Summarize(ms.second)};
  return out;
}

void WriteStatsJson(const std::filesystem::path& path, const TrackArgs& args,
                    const std::vector<FrameRecord>& frames, const StatusSummaries& summaries) {
  nlohmann::ordered_json j = {{"recording", args.recording}, {"map", args.map}, {"threads", args.threads}};
  nlohmann::ordered_json& summary = j["summary"] = nlohmann::ordered_json::object();
  for (const auto& [status, s] : summaries) {
    summary[status] = {{"frames", s.wall.count},     {"median_ms", s.wall.median},
                       {"p95_ms", s.wall.p95},       {"mean_ms", s.wall.mean},
                       {"max_ms", s.wall.max},       {"cpu_median_ms", s.cpu.median},
                       {"cpu_p95_ms", s.cpu.p95}};
  }
  nlohmann::ordered_json& list = j["frames"] = nlohmann::ordered_json::array();
  for (const auto& f : frames) list.push_back(FrameJson(f));
  WriteFileAtomically(path, j.dump(2) + "\n");
}

void RunTrack(const TrackArgs& args) {
  RequireDistinctOutputs({{"--out", args.out}, {"--stats", args.stats}});
  if (args.working_size != 0 && args.working_size < 64)
    throw CommandError("--working-size must be 0 (full resolution) or at least 64 (got " +
                       std::to_string(args.working_size) + ")", 2);
  if (args.sift_size != 0 && args.sift_size < 64)
    throw CommandError("--sift-size must be 0 (the working resolution) or at least 64 (got " +
                       std::to_string(args.sift_size) + ")", 2);
  if (args.reloc_sift_size != 0 && args.reloc_sift_size < 64)
    throw CommandError("--reloc-sift-size must be 0 (as --sift-size) or at least 64 (got " +
                       std::to_string(args.reloc_sift_size) + ")", 2);
  const ScopedSignalCancellation signals;
  cv::setNumThreads(args.threads);
  recordings::Recording rec;
  recordings::ReplayOptions replay;
  rec = recordings::LoadRecording(args.recording);
  if (!args.frames.empty())
    replay.frames = recordings::ParseFrameSpec(args.frames, static_cast<int>(rec.frames.size()));
  const size_t frame_count = replay.frames.empty() ? rec.frames.size() : replay.frames.size();
  map::Map map;
  map = map::LoadMap(args.map);
  if (map.camera.Size() != rec.camera.Size()) {
    std::ostringstream msg;
    msg << args.recording << " has " << rec.camera.width << "x" << rec.camera.height << " frames but the map "
        << args.map << " was built for " << map.camera.width << "x" << map.camera.height;
    throw CommandError(msg.str());
  }
  const tracker::TrackerOptions options = MakeOptions(args);
  std::unique_ptr<tracker::Tracker> tracker;
  try {
    tracker = std::make_unique<tracker::Tracker>(map, options);
  } catch (const tracker::TrackerError& e) {
    throw CommandError(args.map + ": " + e.what());
  } catch (const map::DescriptorIndexError& e) {
    throw CommandError(args.map + ": " + e.what());
  }
  tracker->WarmUp();  // the first frame's timing is then a relocalization's, not a process start's

  // An uncalibrated recording's camera is a guess; its map holds the refined one.
  const tracker::LossDiagnoser diagnoser(map.camera, rec.camera.calibrated ? rec.camera : map.camera, KeyframeAppearance(map, MapFolder(args.map), &rec));
  tracker::LossSummary losses;
  recordings::RecordingSource source(std::move(rec), replay);
  std::vector<FrameRecord> frames;
  recordings::Trajectory trajectory;
  Progress progress("track");
  recordings::Frame frame;
  while (!signals.token().IsCancelled() && source.Next(frame)) {
    // A frame after a gap in --frames has no valid motion prior.
    if (!frames.empty() && frame.index != frames.back().index + 1) tracker->Reset();
    FrameRecord record{static_cast<int>(frame.index), frame.timestamp, tracker->Track(frame.image, frame.timestamp), {}};
    if (record.result.status != tracker::TrackStatus::kLost) {
      trajectory.push_back({record.timestamp, record.result.pose});
    } else {
      record.loss = diagnoser.Diagnose(frame.image, record.result);
      losses.Add(*record.loss);
    }
    frames.push_back(std::move(record));
    if (!signals.token().IsCancelled()) progress.Update(static_cast<long>(frames.size()), static_cast<long>(frame_count),
                    ToString(frames.back().result.status));
  }
  progress.Finish();
  // Interrupted: neither the trajectory nor the statistics are written (a partial trajectory
  // would look complete).
  signals.token().ThrowIfCancelled("stopped after " + std::to_string(frames.size()) + " of " +
                                   std::to_string(frame_count) + " frames; not written: " + args.out +
                                   (args.stats.empty() ? "" : ", " + args.stats));

  recordings::WriteTum(trajectory, args.out, "arview track " + args.recording + " --map " + args.map);
  const StatusSummaries summaries = SummarizeByStatus(frames);
  if (!args.stats.empty()) WriteStatsJson(args.stats, args, frames, summaries);

  std::cout << "localized " << trajectory.size() << "/" << frames.size() << " frames";
  for (const char* status : {"tracking", "relocalized", "lost"}) {
    const auto it = summaries.find(status);
    std::cout << (status == std::string("tracking") ? " (" : ", ") << status << " "
              << (it == summaries.end() ? 0 : it->second.wall.count);
  }
  std::cout << ")\n" << std::fixed << std::setprecision(2);
  const auto aligned = std::count_if(frames.begin(), frames.end(), [](const FrameRecord& f) {
    return f.result.status == tracker::TrackStatus::kTracking && f.result.align_zncc > 0;
  });
  if (aligned > 0)
    std::cout << "  of the tracking frames, " << aligned
              << " took their rotation from image alignment (whip-pans: no feature step could pose them)\n";
  for (const auto& [status, s] : summaries)
    std::cout << "  " << std::left << std::setw(12) << status << std::right << " median " << s.wall.median
              << " ms, p95 " << s.wall.p95 << " ms wall; median " << s.cpu.median << " ms, p95 "
              << s.cpu.p95 << " ms CPU (" << s.wall.count << " frames)\n";
  for (const auto& f : frames)
    if (f.loss) std::cout << "  lost frame " << f.index << ": " << f.result.reason << " — " << tracker::LossHeadline(*f.loss) << "\n";
  const std::vector<std::string> advice = losses.Advice(MapFolder(args.map).string());
  for (size_t i = 0; i < advice.size(); ++i) std::cout << (i == 0 ? "" : "  ") << advice[i] << "\n";
  std::cout << "trajectory: " << args.out << (args.stats.empty() ? "" : ", statistics: " + args.stats) << "\n";
}

}  // namespace

void AddTrackCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("track", "Track a recording against a map and write its trajectory");
  auto a = std::make_shared<TrackArgs>();
  cmd->add_option("recording", a->recording, "Recording folder")->required();
  cmd->add_option("--map", a->map, "Map directory (or its map.arvmap)")->required();
  cmd->add_option("--out", a->out, "TUM trajectory to write (localised frames only)")->required()->check(OutputFileCheck());
  cmd->add_option("--frames", a->frames, "Frames to track, e.g. 1-46:2 (default: all)");
  cmd->add_option("--stats", a->stats, "Per-frame statistics and summary as JSON")->check(OutputFileCheck());
  cmd->add_option("--solver", a->solver, "Minimal solver in RANSAC: kneip | gao | epnp")
      ->capture_default_str()->check(CLI::IsMember({"kneip", "gao", "epnp"}));
  cmd->add_option("--max-features", a->max_features,
                  "SIFT keypoints relocalization extracts (strongest kept) on frames SIFT sees at their own size "
                  "(--sift-size does not reduce them) and that have no prior pose: a set of photos, a video's first "
                  "frame and those after a loss")
      ->capture_default_str()->check(CLI::Range(50, 100000));
  cmd->add_option("--sift-contrast", a->sift_contrast,
                  "SIFT contrast threshold (OpenCV's definition) of relocalization on frames SIFT sees at their own "
                  "size; 0.02 is the test of COLMAP's default peak threshold, with which the map's features were "
                  "extracted (OpenCV's default: 0.04). Below --guided-sift-contrast, flow does not follow a "
                  "relocalization's keypoints: the next frame starts from guided matching")
      ->capture_default_str()->check(CLI::Range(0.001, 0.5));
  cmd->add_option("--reduced-max-features", a->reduced_max_features,
                  "SIFT keypoints relocalization uses when --sift-size reduces the working frame (its own SIFT "
                  "keeps this many; guided matching's features are matched globally through their strongest this many)")
      ->capture_default_str()->check(CLI::Range(50, 100000));
  cmd->add_option("--reduced-sift-contrast", a->reduced_sift_contrast,
                  "SIFT contrast threshold of relocalization when --sift-size reduces the working frame "
                  "(OpenCV's default 0.04: fewer, stronger keypoints, quicker)")
      ->capture_default_str()->check(CLI::Range(0.001, 0.5));
  cmd->add_option("--ratio", a->ratio, "Ratio test of global matching")->capture_default_str()->check(CLI::Range(0.1, 1.0));
  cmd->add_option("--ransac-threshold", a->ransac_threshold_px,
                  "RANSAC's inlier threshold when relocalising, working pixels (the pose is refined on its inliers)")
      ->capture_default_str()->check(CLI::Range(0.1, 50.0));
  cmd->add_option("--tracking-ransac-threshold", a->tracking_ransac_threshold_px,
                  "RANSAC's inlier threshold when tracking and in the wide search, working pixels")
      ->capture_default_str()->check(CLI::Range(0.1, 50.0));
  cmd->add_option("--inlier-threshold", a->inlier_threshold_px,
                  "Inlier threshold after refinement (the inliers counted, followed and gated), working pixels")
      ->capture_default_str()->check(CLI::Range(0.1, 50.0));
  cmd->add_option("--ransac-iterations", a->ransac_iterations, "RANSAC iterations when relocalising")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_option("--min-inliers", a->min_inliers, "Inliers needed to accept a relocalization")
      ->capture_default_str()->check(CLI::Range(6, 100000));
  cmd->add_option("--max-rms", a->max_rms_px, "Largest inlier RMS reprojection error accepted, pixels")
      ->capture_default_str()->check(CLI::Range(0.01, 50.0));
  cmd->add_option("--tracking-min-inliers", a->tracking_min_inliers, "Inliers needed to keep tracking")
      ->capture_default_str()->check(CLI::Range(6, 100000));
  cmd->add_option("--replenish-below", a->replenish_below, "Run guided matching when fewer flow tracks survive")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->add_option("--fresh-features-after", a->fresh_features_after,
                  "A tracked frame that comes more than this many seconds after the last posed one is posed again "
                  "from its own SIFT matched against the whole map, as relocalization does, kept when it agrees with "
                  "the tracked pose: frames far apart (a sub-sampled clip, photos), where optical flow drifts; one SIFT "
                  "extraction a frame more. 0: every tracked frame; -1: never")
      ->capture_default_str()->check(CLI::Range(-1.0, 1e9))->check(NeverOrNotNegative());
  cmd->add_option("--prefetch-below", a->prefetch_below,
                  "Extract guided matching's SIFT ahead, on a worker thread, when fewer flow tracks survive; 0: off "
                  "(in the frame that needs it)")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->add_option("--prefetch-lag", a->prefetch_lag, "Frames after which features extracted ahead are used")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  cmd->add_option("--guided-sift-contrast", a->guided_sift_contrast,
                  "SIFT contrast threshold of guided matching and the wide search (any working size)")
      ->capture_default_str()->check(CLI::Range(0.001, 0.5));
  cmd->add_option("--guided-radius", a->guided_radius_px, "Search radius of guided matching, pixels")
      ->capture_default_str()->check(CLI::Range(1.0, 200.0));
  cmd->add_option("--lk-window", a->lk_window,
                  "Optical flow window side, working pixels (larger follows blur and noise better, costs more)")
      ->capture_default_str()->check(CLI::Range(5, 61));
  cmd->add_option("--lk-levels", a->lk_levels,
                  "Optical flow pyramid levels above the frame (each doubles the motion followed beyond the prediction)")
      ->capture_default_str()->check(CLI::Range(0, 6));
  AddAlignMaxSecondsOption(cmd, a->align_max_seconds);
  cmd->add_option("--index-checks", a->index_checks, "FLANN leaves visited per query (speed vs recall of global matching)")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_option("--working-size", a->working_size,
                  "Longest side of the image the tracker works on (frames larger are reduced; pixel "
                  "options are at this size); 0: full resolution")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->add_option("--sift-size", a->sift_size,
                  "Longest side of the image SIFT runs on (relocalization, guided matching; smaller "
                  "working frames are kept as they are); 0: the working resolution")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->add_option("--reloc-sift-size", a->reloc_sift_size,
                  "Longest side of the image relocalization's own SIFT runs on when --sift-size reduces "
                  "the working frame (working frames up to --sift-size are kept as they are); 0: as --sift-size")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  cmd->add_option("--seed", a->seed, "Seed of RANSAC and of the FLANN index")->capture_default_str();
  cmd->add_option("--threads", a->threads, "OpenCV threads (1 for the measured figures)")
      ->capture_default_str()->check(CLI::Range(1, 256));
  cmd->add_option("--smooth-min-cutoff", a->smoothing_min_cutoff, "One Euro filter: cutoff at rest, Hz")
      ->capture_default_str()->check(CLI::Range(0.001, 1000.0));
  cmd->add_option("--smooth-beta", a->smoothing_beta, "One Euro filter: speed coefficient")
      ->capture_default_str()->check(CLI::Range(0.0, 1000.0));
  cmd->callback([a] { RunTrack(*a); });
}

}  // namespace arview::app
