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
#include <optional>
#include <sstream>

#include "app/cli/commands.h"
#include "app/cli/numeric_flags.h"
#include "app/cli/option_flags.h"
#include "app/cli/output_flags.h"
#include "base/progress.h"
#include "app/cli/session_flags.h"
#include "app/pipeline/stage_stats.h"
#include "app/session/ar_session.h"
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
  std::string room;  // --room: a venue's room, loaded with its neighbours only
  std::string out;
  std::string frames;
  std::string stats;
  std::string solver = ToString(tracker::RelocalizerOptions{}.pose.solver);
  int threads = 1;
  // The tracker flags are bound to these fields: their defaults are TrackerOptions' own.
  tracker::TrackerOptions options;
  OptionFlags flags;
};

tracker::TrackerOptions MakeOptions(const TrackArgs& a) {
  tracker::TrackerOptions o = a.options;
  o.relocalization.pose.solver = tracker::ParseMinimalSolver(a.solver);  // --solver's check let only these through
  o.index.seed = o.relocalization.pose.seed;  // --seed: RANSAC's and the FLANN index's
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
                              {"flow_followed_from", r.flow_followed_from},
                              {"flow_lost_in_view", r.flow_lost_in_view},
                              {"flow_outliers", r.flow_outliers},
                              {"moving_rejected", r.moving_rejected},
                              {"moving_by_patch", r.moving_by_patch},
                              {"moving_by_motion", r.moving_by_motion},
                              {"clipped_rejected", r.clipped_rejected},
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
  if (!r.room.empty()) j["room"] = r.room;  // a venue's map: the room the frame was localized in
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
  const tracker::TrackerOptions options = MakeOptions(args);
  args.flags.Check(options, 2);  // before any file is read; a bad value is a usage error
  const ScopedSignalCancellation signals;
  cv::setNumThreads(args.threads);
  recordings::Recording rec;
  recordings::ReplayOptions replay;
  rec = recordings::LoadRecording(args.recording);
  if (!args.frames.empty())
    replay.frames = recordings::ParseFrameSpec(args.frames, static_cast<int>(rec.frames.size()));
  const size_t frame_count = replay.frames.empty() ? rec.frames.size() : replay.frames.size();
  map::Map map;
  map = LoadSessionMap(args.map, args.room);
  const std::optional<calib::Camera> own_camera = RecordingTrackingCamera(map.camera, rec.camera);
  const calib::Camera camera = own_camera.value_or(map.camera);
  if (camera.Size() != rec.camera.Size()) {
    std::ostringstream msg;
    msg << args.recording << " has " << rec.camera.width << "x" << rec.camera.height << " frames but the map "
        << args.map << " was built for " << map.camera.width << "x" << map.camera.height
        << ", and the recording's camera.yaml is not calibrated (give the recording its camera's calibration: "
           "'arview import ... --camera camera.yaml')";
    throw CommandError(msg.str());
  }
  if (own_camera) {
    std::cerr << "note: the recording's camera (" << camera.width << "x" << camera.height << ", fx " << camera.fx
              << ") differs from the map's (" << map.camera.width << "x" << map.camera.height << ", fx " << map.camera.fx
              << "): its frames are tracked with their own camera\n";
  }
  std::unique_ptr<tracker::Tracker> tracker;
  try {
    tracker = std::make_unique<tracker::Tracker>(map, camera, options);
  } catch (const tracker::TrackerError& e) {
    throw CommandError(args.map + ": " + e.what());
  } catch (const map::DescriptorIndexError& e) {
    throw CommandError(args.map + ": " + e.what());
  }
  tracker->WarmUp();  // the first frame's timing is then a relocalization's, not a process start's

  // The frames are tracked with `camera`, so the cause of a lost frame is never its difference from the map's.
  const tracker::LossDiagnoser diagnoser(camera, camera, KeyframeAppearance(map, MapFolder(args.map), &rec));
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
  tracker::TrackerOptions& o = a->options;
  OptionFlags& f = a->flags;
  cmd->add_option("recording", a->recording, "Recording folder")->required();
  cmd->add_option("--map", a->map, "Map directory (or its map.arvmap)")->required();
  AddRoomOption(cmd, a->room);
  cmd->add_option("--out", a->out, "TUM trajectory to write (localised frames only)")
      ->required()
      ->check(OutputFileCheck());
  cmd->add_option("--frames", a->frames, "Frames to track, e.g. 1-46:2 (default: all)");
  cmd->add_option("--stats", a->stats, "Per-frame statistics and summary as JSON")->check(OutputFileCheck());
  cmd->add_option("--solver", a->solver, "Minimal solver in RANSAC: kneip | gao | epnp")
      ->capture_default_str()
      ->check(CLI::IsMember({"kneip", "gao", "epnp"}));
  f.Add(cmd, "--max-features", ARVIEW_OPTION_FIELD(o, relocalization.features.max_features),
        "SIFT keypoints relocalization extracts (strongest kept) on frames SIFT sees at their own size "
        "(--sift-size does not reduce them) and that have no prior pose: a set of photos, a video's first "
        "frame and those after a loss")
      ->check(CLI::Range(50, 100000));
  f.Add(cmd, "--sift-contrast", ARVIEW_OPTION_FIELD(o, relocalization.features.contrast_threshold),
        "SIFT contrast threshold (OpenCV's definition) of relocalization on frames SIFT sees at their own "
        "size; 0.02 is the test of COLMAP's default peak threshold, with which the map's features were "
        "extracted (OpenCV's default: 0.04). Below --guided-sift-contrast, flow does not follow a "
        "relocalization's keypoints: the next frame starts from guided matching")
      ->check(CLI::Range(0.001, 0.5));
  f.Add(cmd, "--reduced-max-features", ARVIEW_OPTION_FIELD(o, relocalization.reduced_features.max_features),
        "SIFT keypoints relocalization uses when --sift-size reduces the working frame (its own SIFT "
        "keeps this many; guided matching's features are matched globally through their strongest this many)")
      ->check(CLI::Range(50, 100000));
  f.Add(cmd, "--reduced-sift-contrast", ARVIEW_OPTION_FIELD(o, relocalization.reduced_features.contrast_threshold),
        "SIFT contrast threshold of relocalization when --sift-size reduces the working frame "
        "(OpenCV's default 0.04: fewer, stronger keypoints, quicker)")
      ->check(CLI::Range(0.001, 0.5));
  f.Add(cmd, "--ratio", ARVIEW_OPTION_FIELD(o, relocalization.matching.ratio), "Ratio test of global matching")
      ->check(CLI::Range(0.1, 1.0));
  f.Add(cmd, "--keyframe-matching", ARVIEW_OPTION_FIELD(o, relocalization.keyframe_matching),
        "A relocalised frame is matched again to this many keyframes, those that see most of its "
        "pose's inliers, each with a ratio test among its own keypoints, and posed again (0: off)")
      ->check(CLI::Range(0, 1000));
  f.Add(cmd, "--ransac-threshold", ARVIEW_OPTION_FIELD(o, relocalization.pose.ransac_threshold_px),
        "RANSAC's inlier threshold when relocalising, working pixels (the pose is refined on its inliers)")
      ->check(CLI::Range(0.1, 50.0));
  f.Add(cmd, "--tracking-ransac-threshold", ARVIEW_OPTION_FIELD(o, tracking.ransac_threshold_px),
        "RANSAC's inlier threshold when tracking and in the wide search, working pixels")
      ->check(CLI::Range(0.1, 50.0));
  f.Add(cmd, "--inlier-threshold", ARVIEW_OPTION_FIELD(o, relocalization.pose.inlier_threshold_px),
        "Inlier threshold after refinement (the inliers counted, followed and gated), working pixels")
      ->check(CLI::Range(0.1, 50.0));
  f.Add(cmd, "--refine-loss-scale", ARVIEW_OPTION_FIELD(o, relocalization.pose.refinement.loss_scale_px),
        "Where the Cauchy loss of a relocalization's refinement bends, working pixels (COLMAP's image "
        "registration's; 2 until 2026-12-07, what tracked frames keep: --tracking-refine-loss-scale)")
      ->check(CLI::Range(0.1, 50.0));
  f.Add(cmd, "--tracking-refine-loss-scale", ARVIEW_OPTION_FIELD(o, tracking.refine_loss_scale_px),
        "Where the Cauchy loss of a tracked frame's refinement bends, working pixels")
      ->check(CLI::Range(0.1, 50.0));
  f.Add(cmd, "--ransac-iterations", ARVIEW_OPTION_FIELD(o, relocalization.pose.ransac_max_iterations),
        "RANSAC iterations when relocalising")
      ->check(CLI::Range(1, 1000000));
  f.Add(cmd, "--min-inliers", ARVIEW_OPTION_FIELD(o, relocalization.pose.min_inliers),
        "Inliers needed to accept a relocalization")
      ->check(CLI::Range(6, 100000));
  f.Add(cmd, "--max-rms", ARVIEW_OPTION_FIELD(o, relocalization.pose.max_rms_px),
        "Largest inlier RMS reprojection error accepted, pixels")
      ->check(CLI::Range(0.01, 50.0));
  f.Add(cmd, "--tracking-min-inliers", ARVIEW_OPTION_FIELD(o, tracking.min_inliers), "Inliers needed to keep tracking")
      ->check(CLI::Range(6, 100000));
  f.Add(cmd, "--max-flow-tracks", ARVIEW_OPTION_FIELD(o, tracking.max_flow_tracks),
        "At most this many inliers are followed into the next frame by optical flow, spread over the image")
      ->check(CLI::Range(1, 100000));
  f.Add(cmd, "--replenish-below", ARVIEW_OPTION_FIELD(o, tracking.replenish_below),
        "Run guided matching when fewer flow tracks survive")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--occlusion-credit", ARVIEW_OPTION_FIELD(o, tracking.research.occlusion_credit_frames),
        "Flow tracks the patch test dropped (something walked over their points) count toward "
        "--replenish-below for this many tracked frames, as expected back, while the tracks followed are "
        "at least half of it and lie in 3 of the frame's 4 quadrants; 0: off (a plain count)")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--research-every", ARVIEW_OPTION_FIELD(o, tracking.research.max_frames_between),
        "A tracked frame this many frames after the last re-search (guided matching) re-searches whatever "
        "its flow tracks' count: tracks followed for a while drift together (a live session extracts its "
        "SIFT ahead); 0: never")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--clipped-window-share", ARVIEW_OPTION_FIELD(o, tracking.clipped.max_share),
        "Drop a flow track before the pose when more than this share of its LK window is clipped white "
        "(grey 250 or more: a lamp switched on under a raised exposure); 1: off")
      ->check(CLI::Range(0.01, 1.0));
  f.Add(cmd, "--fresh-features-after", ARVIEW_OPTION_FIELD(o, tracking.fresh_features_after_s),
        "A tracked frame that comes more than this many seconds after the last posed one is posed again "
        "from its own SIFT matched against the whole map, as relocalization does, kept when it agrees with "
        "the tracked pose: frames far apart (a sub-sampled clip, photos), where optical flow drifts; one SIFT "
        "extraction a frame more. 0: every tracked frame; -1: never")
      ->check(CLI::Range(-1.0, 1e9))
      ->check(NeverOrNotNegative());
  f.Add(cmd, "--prefetch-below", ARVIEW_OPTION_FIELD(o, tracking.prefetch_below),
        "Extract guided matching's SIFT ahead, on a worker thread, when fewer flow tracks survive; 0: off "
        "(in the frame that needs it)")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--prefetch-lag", ARVIEW_OPTION_FIELD(o, tracking.prefetch_lag_frames),
        "Frames after which features extracted ahead are used")
      ->check(CLI::Range(1, 1000));
  f.Add(cmd, "--guided-sift-contrast", ARVIEW_OPTION_FIELD(o, tracking.guided_contrast_threshold),
        "SIFT contrast threshold of guided matching and the wide search (any working size)")
      ->check(CLI::Range(0.001, 0.5));
  f.Add(cmd, "--guided-radius", ARVIEW_OPTION_FIELD(o, tracking.guided_radius_px),
        "Search radius of guided matching, pixels")
      ->check(CLI::Range(1.0, 200.0));
  f.Add(cmd, "--lk-window", ARVIEW_OPTION_FIELD(o, tracking.lk_window_px),
        "Optical flow window side, working pixels (larger follows blur and noise better, costs more)")
      ->check(CLI::Range(5, 61));
  f.Add(cmd, "--lk-levels", ARVIEW_OPTION_FIELD(o, tracking.lk_pyramid_levels),
        "Optical flow pyramid levels above the frame (each doubles the motion followed beyond the prediction)")
      ->check(CLI::Range(0, 6));
  AddAlignMaxSecondsOption(cmd, o.tracking.align_max_seconds);
  f.Name("tracking.align_max_seconds", "--align-max-seconds");
  f.Add(cmd, "--index-checks", ARVIEW_OPTION_FIELD(o, index.checks),
        "FLANN leaves visited per query (speed vs recall of global matching)")
      ->check(CLI::Range(1, 100000));
  f.Add(cmd, "--working-size", ARVIEW_OPTION_FIELD(o, working_long_side),
        "Longest side of the image the tracker works on (frames larger are reduced; pixel "
        "options are at this size); 0: full resolution")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--sift-size", ARVIEW_OPTION_FIELD(o, relocalization.sift_long_side),
        "Longest side of the image SIFT runs on (relocalization, guided matching; smaller "
        "working frames are kept as they are); 0: the working resolution")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--sift-own-size", ARVIEW_OPTION_FIELD(o, relocalization.sift_own_size_up_to),
        "Working frames up to this longest side are given to SIFT at their own size with the "
        "--max-features and --sift-contrast settings, whatever --sift-size says (still photos: "
        "relocalization's SIFT is their pose's precision); 0: none")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--reloc-sift-size", ARVIEW_OPTION_FIELD(o, relocalization.reloc_sift_long_side),
        "Longest side of the image relocalization's own SIFT runs on when --sift-size reduces "
        "the working frame (working frames up to --sift-size are kept as they are); 0: as --sift-size")
      ->check(CLI::Range(0, 100000));
  f.Add(cmd, "--seed", ARVIEW_OPTION_FIELD(o, relocalization.pose.seed), "Seed of RANSAC and of the FLANN index");
  f.Name("index.seed", "--seed");
  cmd->add_option("--threads", a->threads, "OpenCV threads (1 for the measured figures)")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  f.Add(cmd, "--smooth-min-cutoff", ARVIEW_OPTION_FIELD(o, smoothing.min_cutoff_hz),
        "One Euro filter: cutoff at rest, Hz")
      ->check(CLI::Range(0.001, 1000.0));
  f.Add(cmd, "--smooth-beta", ARVIEW_OPTION_FIELD(o, smoothing.beta), "One Euro filter: speed coefficient")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->callback([a] { RunTrack(*a); });
}

}  // namespace arview::app
