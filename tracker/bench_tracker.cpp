// bench_tracker: speed of the tracker's stages and a side-by-side of the pose solver against
// OpenCV's solvePnPRansac + solvePnPRefineLM on the same correspondences.
//
//   bench_tracker [--map=<map-dir> --recording=<recording> [--frames=<spec>]] [benchmark flags]
//
// Without --map, the real-frame benchmarks run on renderings of a real photograph (opencv-doc's
// graf1.png) on a plane, with a map built from SIFT on rendered keyframes. With --map and
// --recording, relocalization and SIFT run on the recording's frames (e.g. templeRing's odd
// frames against the map of its even frames) and continuous tracking runs over them in order,
// back and forth. Single-threaded: cv::setNumThreads(1).

#include <Eigen/Core>
#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <optional>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "map/map_file.h"
#include "tracker/brightness_match.h"
#include "tracker/clipped_windows.h"
#include "tracker/research_trigger.h"
#include "tracker/moving_tracks.h"
#include "recordings/accuracy.h"
#include "recordings/recording.h"
#include "base/heap_reuse.h"
#include "base/stats.h"
#include "tracker/refine_pose_ceres_reference.h"
#include "tracker/test_planar_scene.h"
#include "tracker/test_scene.h"
#include "tracker/tracker.h"

namespace arview::tracker {
namespace {

// ---------------------------------------------------------------------------------------------
// Pose solver on synthetic correspondences with exact ground truth: 300 points, 30% outliers,
// 0.7 px noise, the distorted 640x480 test camera. Both solvers get the same distorted pixels.

constexpr int kScenes = 32;
constexpr double kThresholdPx = 4.0;

const std::vector<testing::SyntheticScene>& Scenes() {
  static const auto scenes = [] {
    std::vector<testing::SyntheticScene> s;
    for (int i = 0; i < kScenes; ++i) s.push_back(testing::MakeScene(testing::TestCamera(), 300, 0.7, 0.3, 1000 + i));
    return s;
  }();
  return scenes;
}

struct ErrorAccumulator {
  double centre_mm = 0, rotation_deg = 0, inliers = 0;
  int count = 0, failures = 0;
  void Add(bool ok, const calib::Pose& estimate, const calib::Pose& truth, int n_inliers) {
    if (!ok) {
      ++failures;
      return;
    }
    centre_mm += 1000.0 * (estimate.Center() - truth.Center()).norm();
    rotation_deg += testing::RotationErrorDeg(estimate, truth);
    inliers += n_inliers;
    ++count;
  }
  void Report(benchmark::State& state) const {
    state.counters["centre_err_mm"] = count ? centre_mm / count : -1;
    state.counters["rot_err_deg"] = count ? rotation_deg / count : -1;
    state.counters["inliers"] = count ? inliers / count : 0;
    state.counters["failures"] = failures;
  }
};

void BM_PoseSolver_OpenGV_LM(benchmark::State& state) {
  const calib::Camera camera = testing::TestCamera();
  AbsolutePoseOptions options;
  options.solver = static_cast<MinimalSolver>(state.range(0));
  options.ransac_threshold_px = kThresholdPx;
  options.inlier_threshold_px = kThresholdPx;
  ErrorAccumulator errors;
  size_t i = 0;
  double ransac_ms = 0, refine_ms = 0;
  for (auto _ : state) {
    const auto& scene = Scenes()[i++ % kScenes];
    options.seed = static_cast<std::uint32_t>(i);
    const AbsolutePoseResult r = EstimateAbsolutePose(camera, scene.pixels, scene.points, options);
    benchmark::DoNotOptimize(r.pose);
    errors.Add(r.ok, r.pose, scene.pose, r.stats.inliers);
    ransac_ms += r.stats.ransac_ms;
    refine_ms += r.stats.refine_ms;
  }
  errors.Report(state);
  state.counters["ransac_ms"] = ransac_ms / state.iterations();
  state.counters["refine_ms"] = refine_ms / state.iterations();
  state.SetLabel(ToString(options.solver));
}
BENCHMARK(BM_PoseSolver_OpenGV_LM)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

// The refinement alone, as a tracked frame runs it: 250 correspondences with 0.7 px noise and
// 10% outliers, Cauchy loss at 2 px, from a start 0.5 deg and 2 cm off. Arg 0: arview's
// Levenberg-Marquardt with analytic Jacobians (RefinePose); arg 1: the same cost in Ceres
// (autodiff, quaternion manifold), as the tracker solved it until 2026-12-02.
void BM_RefinePose(benchmark::State& state) {
  const calib::Camera camera = testing::TestCamera();
  std::vector<testing::SyntheticScene> scenes;
  for (int i = 0; i < kScenes; ++i) scenes.push_back(testing::MakeScene(camera, 250, 0.7, 0.1, 2000 + i));
  const bool with_ceres = state.range(0) == 1;
  size_t i = 0;
  double centre_mm = 0;
  for (auto _ : state) {
    const auto& scene = scenes[i++ % kScenes];
    calib::Pose start = scene.pose;
    start.t_cw += Eigen::Vector3d(0.012, -0.01, 0.012);
    start.q_cw = start.q_cw * Eigen::Quaterniond(Eigen::AngleAxisd(0.0087, Eigen::Vector3d::UnitX()));
    const calib::Pose refined = with_ceres
        ? testing::RefinePoseWithCeres(camera, scene.pixels, scene.points, start, {})
        : RefinePose(camera, scene.pixels, scene.points, start, {}).pose;
    benchmark::DoNotOptimize(refined);
    centre_mm += 1000.0 * (refined.Center() - scene.pose.Center()).norm();
  }
  state.counters["centre_err_mm"] = centre_mm / static_cast<double>(state.iterations());
  state.SetLabel(with_ceres ? "ceres-autodiff" : "arview-lm");
}
BENCHMARK(BM_RefinePose)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Issue 58's added rejection, per tracked frame as the tracker runs it at 640x480: the brightness
// check of the frame LK follows into (both means; no scaling, an ordinary frame), the moving-track
// filter over max_flow_tracks flow tracks (a tenth of them on a mover), and the mover's region
// checked for 300 guided matches. The bound: 0.3 ms.
static void BM_MovingTrackRejection(benchmark::State& state) {
  constexpr int kTracks = 300, kGuided = 300;
  cv::Mat frame(480, 640, CV_8U), reference(480, 640, CV_8U);
  cv::randu(frame, 30, 220);
  frame.convertTo(reference, CV_8U, 1.01);
  std::vector<std::uint32_t> ids(kTracks);
  std::vector<Eigen::Vector2d> pixels(kTracks), predicted(kTracks), guided(kGuided);
  std::vector<float> errors(kTracks);
  for (int i = 0; i < kTracks; ++i) {
    ids[i] = static_cast<std::uint32_t>(i * 13);
    predicted[i] = Eigen::Vector2d(20.0 * (i % 30) + 10, 16.0 * (i / 30) + 8);
    pixels[i] = predicted[i] + Eigen::Vector2d(1.5, -0.5) + (i % 10 == 0 ? Eigen::Vector2d(6, 0) : Eigen::Vector2d::Zero());
    errors[i] = i % 10 == 0 ? 30.f : 3.f + 0.01f * static_cast<float>(i % 7);
  }
  for (int i = 0; i < kGuided; ++i) guided[i] = Eigen::Vector2d((i * 37) % 640, (i * 53) % 480);
  MovingTrackFilter filter({}, kTracks * 13);
  std::uint32_t frame_number = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(MatchMeanBrightness(frame, reference, 0.05).image.data);
    const MovingTrackVerdict verdict = filter.Judge({ids, pixels, predicted, errors}, ++frame_number);
    int near = 0;
    for (const Eigen::Vector2d& g : guided) near += MovingTrackFilter::NearRejected(verdict, g, 16);
    benchmark::DoNotOptimize(near);
  }
}
BENCHMARK(BM_MovingTrackRejection)->Unit(benchmark::kMicrosecond);

// The fourth round's rules switched on (docs/tracker.md, "Fourth round"), per tracked frame at
// 640x480: the clipped-window test of 300 flow tracks and 300 guided matches (a third of the
// frame clipped white), and the re-search trigger over 140 tracks with credit kept.
static void BM_ClippedWindowsAndResearchTrigger(benchmark::State& state) {
  constexpr int kTracks = 300;
  cv::Mat frame(480, 640, CV_8U);
  cv::randu(frame, 30, 220);
  frame.colRange(0, 213).setTo(255);
  std::vector<Eigen::Vector2d> tracks(kTracks), guided(kTracks);
  for (int i = 0; i < kTracks; ++i) {
    tracks[i] = Eigen::Vector2d(20.0 * (i % 30) + 10, 16.0 * (i / 30) + 8);
    guided[i] = Eigen::Vector2d((i * 37) % 640, (i * 53) % 480);
  }
  ClippedWindowOptions clipped;
  clipped.max_share = 0.5;
  ResearchTriggerOptions research;
  research.occlusion_credit_frames = 30;
  ResearchTrigger trigger(research, 150);
  const std::span<const Eigen::Vector2d> followed = std::span(tracks).first(140);
  std::uint32_t frame_number = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(MostlyClipped(frame, tracks, 11, clipped));
    benchmark::DoNotOptimize(MostlyClipped(frame, guided, 11, clipped));
    trigger.Occluded(++frame_number, 6);
    benchmark::DoNotOptimize(trigger.Due(frame_number, followed, frame.size()));
  }
}
BENCHMARK(BM_ClippedWindowsAndResearchTrigger)->Unit(benchmark::kMicrosecond);

// OpenCV's pipeline on the same input: solvePnPRansac (same threshold, iterations and
// confidence) then solvePnPRefineLM on its inliers.
bool OpenCvPose(const calib::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                const std::vector<Eigen::Vector3d>& points, int flags, calib::Pose* pose, int* n_inliers) {
  const cv::Mat K(camera.K()), dist = camera.DistCoeffs();
  std::vector<cv::Point2d> image;
  std::vector<cv::Point3d> object;
  for (size_t j = 0; j < pixels.size(); ++j) {
    image.emplace_back(pixels[j].x(), pixels[j].y());
    object.emplace_back(points[j].x(), points[j].y(), points[j].z());
  }
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  if (!cv::solvePnPRansac(object, image, K, dist, rvec, tvec, false, 1000, static_cast<float>(kThresholdPx), 0.999,
                          inliers, flags) ||
      inliers.size() < 6)
    return false;
  std::vector<cv::Point2d> in_image;
  std::vector<cv::Point3d> in_object;
  for (int k : inliers) {
    in_image.push_back(image[k]);
    in_object.push_back(object[k]);
  }
  cv::solvePnPRefineLM(in_object, in_image, K, dist, rvec, tvec);
  *pose = calib::PoseFromOpenCv(rvec, tvec);
  *n_inliers = static_cast<int>(inliers.size());
  return true;
}

const char* OpenCvFlagName(int flags) {
  return flags == cv::SOLVEPNP_P3P ? "P3P" : flags == cv::SOLVEPNP_AP3P ? "AP3P" : "EPNP";
}

void BM_PoseSolver_OpenCV_RansacRefineLM(benchmark::State& state) {
  const calib::Camera camera = testing::TestCamera();
  const int flags = static_cast<int>(state.range(0));
  ErrorAccumulator errors;
  size_t i = 0;
  for (auto _ : state) {
    const auto& scene = Scenes()[i++ % kScenes];
    calib::Pose pose;
    int inliers = 0;
    const bool ok = OpenCvPose(camera, scene.pixels, scene.points, flags, &pose, &inliers);
    errors.Add(ok, pose, scene.pose, inliers);
  }
  errors.Report(state);
  state.SetLabel(OpenCvFlagName(flags));
}
BENCHMARK(BM_PoseSolver_OpenCV_RansacRefineLM)
    ->Arg(cv::SOLVEPNP_P3P)
    ->Arg(cv::SOLVEPNP_AP3P)
    ->Arg(cv::SOLVEPNP_EPNP)
    ->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------------------------------------
// Real frames: a recording + its map, or renderings of a real photograph on a plane.

struct RealFrames {
  map::Map map;
  std::vector<cv::Mat> frames;  // in sequence order
  std::string source;
  // Per frame, the true camera centre in the map's world (ground truth mapped by the inverse
  // of the Sim(3) fitted from the map's keyframes to the ground truth), when known.
  std::vector<std::optional<Eigen::Vector3d>> true_centre;
  double map_to_mm = 1000;  // map units → millimetres of the ground truth's world
};

std::string g_map_dir, g_recording_dir, g_frames_spec;

std::unique_ptr<RealFrames> LoadRealFrames() {
  auto real = std::make_unique<RealFrames>();
  if (!g_map_dir.empty()) {
    real->map = map::LoadMap(g_map_dir);
    const recordings::Recording rec = recordings::LoadRecording(g_recording_dir);
    const std::vector<int> indices =
        recordings::ParseFrameSpec(g_frames_spec.empty() ? "0-" + std::to_string(rec.frames.size() - 1) : g_frames_spec,
                                   static_cast<int>(rec.frames.size()));
    std::optional<recordings::Sim3> to_truth;
    if (rec.groundtruth) {
      recordings::Trajectory keyframes;
      for (const auto& k : real->map.keyframes) keyframes.push_back({k.timestamp, k.pose});
      to_truth = recordings::FitAlignment(keyframes, *rec.groundtruth, recordings::AlignMode::kSim3, 0.02);
      real->map_to_mm = 1000 * to_truth->scale;
    }
    for (int i : indices) {
      real->frames.push_back(rec.ReadImage(i));
      std::optional<Eigen::Vector3d> centre;
      if (to_truth) {
        for (const auto& g : *rec.groundtruth)
          if (std::abs(g.timestamp - rec.frames[i].timestamp) < 1e-6) centre = to_truth->Inverse()(g.pose.Center());
      }
      real->true_centre.push_back(centre);
    }
    real->source = g_recording_dir;
    return real;
  }
  const cv::Mat texture = cv::imread("/usr/share/doc/opencv-doc/examples/data/graf1.png");
  if (texture.empty()) return nullptr;
  const testing::PlanarWorld world(texture, testing::TestCamera(), 0.0015);
  using testing::LookAt;
  real->map = world.MakeMap({LookAt({0, 0, -0.9}, {0, 0, 0}), LookAt({0.3, 0, -0.85}, {0.05, 0, 0}),
                             LookAt({-0.3, 0.1, -0.85}, {-0.05, 0, 0}), LookAt({0, -0.25, -0.85}, {0, -0.05, 0})},
                            SiftExtractor());
  for (int i = 0; i < 60; ++i) {
    const double a = 0.004 * i;
    const calib::Pose pose = LookAt({-0.15 + a, 0.05 * std::sin(3 * a), -0.8 - 0.1 * a}, {0.02, 0, 0});
    real->frames.push_back(world.Render(pose));
    real->true_centre.push_back(pose.Center());
  }
  real->source = "graf1.png on a plane";
  return real;
}

const RealFrames* Real() {
  static const std::unique_ptr<RealFrames> real = LoadRealFrames();
  return real.get();
}

void BM_SiftExtract(benchmark::State& state) {
  const RealFrames* real = Real();
  if (!real) return state.SkipWithError("no frames (opencv-doc missing, no --map)");
  FeatureOptions options;
  options.max_features = static_cast<int>(state.range(0));
  const SiftExtractor sift(options);
  size_t i = 0;
  double keypoints = 0;
  for (auto _ : state) {
    const Features f = sift.Extract(real->frames[i++ % real->frames.size()]);
    keypoints += f.keypoints.size();
  }
  state.counters["keypoints"] = keypoints / state.iterations();
  state.SetLabel(real->source);
}
BENCHMARK(BM_SiftExtract)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

// One relocalization per frame: the tracker forgets its prior before each. Counts the frames
// localized and the inliers, per iteration. Returns the tracker's working camera.
calib::Camera RelocalizeEveryFrame(benchmark::State& state, const RealFrames& real, const TrackerOptions& options) {
  Tracker tracker(real.map, options);
  size_t i = 0;
  int localized = 0;
  double inliers = 0;
  for (auto _ : state) {
    tracker.Reset();
    const FrameResult r = tracker.Track(real.frames[i % real.frames.size()], static_cast<double>(i));
    ++i;
    localized += r.status != TrackStatus::kLost;
    inliers += r.inliers;
  }
  state.counters["localized_ratio"] = static_cast<double>(localized) / state.iterations();
  state.counters["inliers"] = inliers / static_cast<double>(state.iterations());
  return tracker.working_camera();
}

void BM_Relocalize(benchmark::State& state) {
  const RealFrames* real = Real();
  if (!real) return state.SkipWithError("no frames (opencv-doc missing, no --map)");
  TrackerOptions options;
  options.relocalization.features.max_features = static_cast<int>(state.range(0));
  options.relocalization.reduced_features.max_features = static_cast<int>(state.range(1));
  options.relocalization.sift_long_side = static_cast<int>(state.range(2));
  options.relocalization.reloc_sift_long_side = static_cast<int>(state.range(3));
  const calib::Camera working = RelocalizeEveryFrame(state, *real, options);
  const int reloc_side = RelocSiftLongSide(working, options.relocalization);
  state.SetLabel(real->source + ", SIFT at longest side " +
                 (reloc_side > 0 ? std::to_string(reloc_side) : std::string("working")));
}
// Arguments: max_features, reduced_max_features, RelocalizerOptions::sift_long_side (0: the
// working resolution), reloc_sift_long_side (0: as sift_long_side). On 640x480 frames 640 and 0
// are the same image and neither reduced_features nor reloc_sift_long_side applies; the
// defaults are {1000, 1000, 640, 480}.
BENCHMARK(BM_Relocalize)
    ->Args({1000, 1000, 640, 480})
    ->Args({2000, 1000, 640, 480})
    ->Args({2000, 2000, 640, 480})
    ->Args({2000, 1000, 640, 0})
    ->Args({2000, 1000, 0, 0})
    ->Unit(benchmark::kMillisecond);

// One relocalization per frame with the default options, matched again keyframe by keyframe to
// this many keyframes (RelocalizerOptions::keyframe_matching; 0: the global matches alone).
void BM_RelocalizeKeyframeMatching(benchmark::State& state) {
  const RealFrames* real = Real();
  if (!real) return state.SkipWithError("no frames (opencv-doc missing, no --map)");
  TrackerOptions options;
  options.relocalization.keyframe_matching = static_cast<int>(state.range(0));
  RelocalizeEveryFrame(state, *real, options);
  state.SetLabel(real->source);
}
BENCHMARK(BM_RelocalizeKeyframeMatching)->Arg(0)->Arg(5)->Unit(benchmark::kMillisecond);

// Continuous tracking over the frames in order, back and forth (no jump at the ends).
void BM_TrackContinuous(benchmark::State& state) {
  const RealFrames* real = Real();
  if (!real) return state.SkipWithError("no frames (opencv-doc missing, no --map)");
  Tracker tracker(real->map);
  const size_t n = real->frames.size();
  const auto ping_pong = [n](size_t k) { return n < 2 ? 0 : (k / (n - 1)) % 2 == 0 ? k % (n - 1) : (n - 1) - k % (n - 1); };
  // The first frame is a relocalization: done before timing starts.
  tracker.Track(real->frames[0], 0.0);
  size_t k = 1;
  int tracked = 0, replenished = 0;
  StageTimes sum;
  for (auto _ : state) {
    const FrameResult r = tracker.Track(real->frames[ping_pong(k)], k / 30.0);
    ++k;
    tracked += r.status == TrackStatus::kTracking;
    replenished += r.keypoints > 0;
    sum.flow_ms += r.times.flow_ms;
    sum.extract_ms += r.times.extract_ms;
    sum.match_ms += r.times.match_ms;
    sum.ransac_ms += r.times.ransac_ms;
    sum.refine_ms += r.times.refine_ms;
  }
  const double n_iter = static_cast<double>(state.iterations());
  state.counters["tracking_ratio"] = tracked / n_iter;
  state.counters["sift_ratio"] = replenished / n_iter;
  state.counters["flow_ms"] = sum.flow_ms / n_iter;
  state.counters["extract_ms"] = sum.extract_ms / n_iter;
  state.counters["match_ms"] = sum.match_ms / n_iter;
  state.counters["ransac_ms"] = sum.ransac_ms / n_iter;
  state.counters["refine_ms"] = sum.refine_ms / n_iter;
  state.SetLabel(real->source);
}
BENCHMARK(BM_TrackContinuous)->Unit(benchmark::kMillisecond);

// The tracking thread's time per frame as a live pipeline sees it: the frames in order, delivered
// at 30 fps (the wait for the next frame is not timed), the tracker's steps in line (Arg 0:
// guided matching's SIFT and relocalization on the frame that needs them) or on its worker (Arg
// 1: TrackingOptions::background, prefetch_below kBackgroundPrefetchBelow). The counters are the
// distribution of Track()'s wall time over the frames; with the worker its SIFT runs beside the
// timed calls, on the other core. The first frame's relocalization is part of it.
void BM_TrackAtCameraRate(benchmark::State& state) {
  const RealFrames* real = Real();
  if (!real) return state.SkipWithError("no frames (opencv-doc missing, no --map)");
  TrackerOptions options;
  if (state.range(0) == 1) {
    options.tracking.background = true;
    options.tracking.prefetch_below = kBackgroundPrefetchBelow;
  }
  std::vector<double> track_ms;
  int tracked = 0, relocalized = 0, lost = 0, extracted_ahead = 0;
  for (auto _ : state) {
    Tracker tracker(real->map, options);
    tracker.WarmUp();
    track_ms.clear();
    auto next = std::chrono::steady_clock::now();
    for (size_t k = 0; k < real->frames.size(); ++k) {
      state.PauseTiming();
      next += std::chrono::microseconds(33333);
      std::this_thread::sleep_until(next);
      state.ResumeTiming();
      const auto start = std::chrono::steady_clock::now();
      const FrameResult r = tracker.Track(real->frames[k], static_cast<double>(k) / 30.0);
      track_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      tracked += r.status == TrackStatus::kTracking;
      relocalized += r.status == TrackStatus::kRelocalized;
      lost += r.status == TrackStatus::kLost;
      extracted_ahead += r.prefetched_matches > 0;
    }
  }
  const double frames = static_cast<double>(state.iterations()) * static_cast<double>(real->frames.size());
  state.counters["p50_ms"] = Percentile(track_ms, 0.50);
  state.counters["p99_ms"] = Percentile(track_ms, 0.99);
  state.counters["max_ms"] = *std::max_element(track_ms.begin(), track_ms.end());
  state.counters["tracking_ratio"] = tracked / frames;
  state.counters["relocalized_ratio"] = relocalized / frames;
  state.counters["lost_ratio"] = lost / frames;
  state.counters["ahead_ratio"] = extracted_ahead / frames;
  state.SetLabel(real->source + (state.range(0) == 1 ? ", worker" : ", in line"));
}
BENCHMARK(BM_TrackAtCameraRate)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kMillisecond);

// Continuous tracking of the planar scene (graf1.png) rendered at 640x480, 1280x720 and
// 1920x1080 with the same field of view and distortion: the tracker reduces the larger frames
// to its working resolution (longest side 960), so the per-frame cost grows only by the
// reduction and the final refinement on the full camera. Forward then back over 60 frames.
struct PlanarAtSize {
  map::Map map;
  std::vector<cv::Mat> frames;
};

const PlanarAtSize* PlanarFramesAt(int width, int height) {
  static std::map<int, std::unique_ptr<PlanarAtSize>> cache;
  auto& slot = cache[width];
  if (slot) return slot.get();
  const cv::Mat texture = cv::imread("/usr/share/doc/opencv-doc/examples/data/graf1.png");
  if (texture.empty()) return nullptr;
  const double s = width / 640.0;
  calib::Camera camera = calib::Camera::Pinhole(width, height, 520.0 * s, 518.0 * s, (width - 1) / 2.0 + 3.0 * s,
                                                (height - 1) / 2.0 + 1.5 * s);
  camera.dist = testing::TestCamera().dist;
  const testing::PlanarWorld world(texture, camera, 0.0015);
  using testing::LookAt;
  slot = std::make_unique<PlanarAtSize>();
  slot->map = world.MakeMap({LookAt({0, 0, -0.9}, {0, 0, 0}), LookAt({0.3, 0, -0.85}, {0.05, 0, 0}),
                             LookAt({-0.3, 0.1, -0.85}, {-0.05, 0, 0}), LookAt({0, -0.25, -0.85}, {0, -0.05, 0})},
                            SiftExtractor());
  for (int i = 0; i < 60; ++i) {
    const double a = 0.004 * i;
    slot->frames.push_back(world.Render(LookAt({-0.15 + a, 0.05 * std::sin(3 * a), -0.8 - 0.1 * a}, {0.02, 0, 0})));
  }
  return slot.get();
}

void BM_TrackPlanarAtSize(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0)), height = static_cast<int>(state.range(1));
  const PlanarAtSize* scene = PlanarFramesAt(width, height);
  if (!scene) return state.SkipWithError("graf1.png missing (Debian package opencv-doc)");
  Tracker tracker(scene->map);
  const size_t n = scene->frames.size();
  tracker.Track(scene->frames[0], 0.0);
  size_t k = 1;
  int tracked = 0;
  double cpu_ms = 0;
  for (auto _ : state) {
    const size_t i = (k / (n - 1)) % 2 == 0 ? k % (n - 1) : (n - 1) - k % (n - 1);
    const FrameResult r = tracker.Track(scene->frames[i], k / 30.0);
    ++k;
    tracked += r.status == TrackStatus::kTracking;
    cpu_ms += r.times.cpu_ms;
  }
  state.counters["tracking_ratio"] = tracked / static_cast<double>(state.iterations());
  state.counters["cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
  state.SetLabel(std::to_string(width) + "x" + std::to_string(height) + ", working " +
                 std::to_string(tracker.working_camera().width) + "x" + std::to_string(tracker.working_camera().height));
}
BENCHMARK(BM_TrackPlanarAtSize)->Args({640, 480})->Args({1280, 720})->Args({1920, 1080})->Unit(benchmark::kMillisecond);

// A whip-pan frame's rotation by image alignment (tracker/rotation_aligner.h): both frames shrunk
// to the small images (80 and 40 px wide) and aligned, from a prediction 3 degrees off. The
// frames are the planar scene's at 640x480 and 960x540 (the working image of 1920x1080).
void BM_AlignRotation(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0)), height = static_cast<int>(state.range(1));
  const PlanarAtSize* scene = PlanarFramesAt(width, height);
  if (!scene) return state.SkipWithError("graf1.png missing (Debian package opencv-doc)");
  const cv::Mat& a = scene->frames[10];
  const cv::Mat& b = scene->frames[20];
  const calib::Camera& camera = scene->map.camera;
  const RotationAlignerOptions options;
  const Eigen::Quaterniond initial(Eigen::AngleAxisd(3.0 * M_PI / 180, Eigen::Vector3d::UnitY()));
  int ok = 0;
  for (auto _ : state) {
    const SmallImage reference(a, camera, options), current(b, camera, options);
    const RotationAlignment r = AlignRotation(reference, current, initial, options);
    ok += r.ok;
    benchmark::DoNotOptimize(r.rotation);
  }
  state.counters["ok_ratio"] = ok / static_cast<double>(state.iterations());
}
BENCHMARK(BM_AlignRotation)->Args({640, 480})->Args({960, 540})->Unit(benchmark::kMillisecond);

// The same side-by-side on real correspondences: each frame's SIFT matched to the map (as
// relocalization does), solved by both. With --map/--recording and ground truth, the error is
// the camera-centre distance after the Sim(3) fitted on the map's keyframes.
struct RealCorrespondences {
  std::vector<std::vector<Eigen::Vector2d>> pixels;
  std::vector<std::vector<Eigen::Vector3d>> points;
  std::vector<std::optional<Eigen::Vector3d>> true_centre;  // in the map's world
};

const RealCorrespondences* RealMatches() {
  static const std::unique_ptr<RealCorrespondences> matches = []() -> std::unique_ptr<RealCorrespondences> {
    const RealFrames* real = Real();
    if (!real) return nullptr;
    auto out = std::make_unique<RealCorrespondences>();
    const map::DescriptorIndex index(real->map.descriptors);
    const SiftExtractor sift;
    for (size_t f = 0; f < real->frames.size(); ++f) {
      const Features features = sift.Extract(real->frames[f]);
      std::vector<Eigen::Vector2d> px;
      std::vector<Eigen::Vector3d> pts;
      GatherCorrespondences(features, real->map, MatchToMap(features, real->map, index, {}), &px, &pts);
      out->pixels.push_back(std::move(px));
      out->points.push_back(std::move(pts));
      out->true_centre.push_back(real->true_centre[f]);
    }
    return out;
  }();
  return matches.get();
}

struct RealErrors {
  std::vector<double> centre_mm;
  int failures = 0;
  double inliers = 0;
  void Add(bool ok, const calib::Pose& pose, const std::optional<Eigen::Vector3d>& truth, double scale_to_mm,
           int n_inliers) {
    if (!ok) {
      ++failures;
      return;
    }
    inliers += n_inliers;
    if (truth) centre_mm.push_back(scale_to_mm * (pose.Center() - *truth).norm());
  }
  void Report(benchmark::State& state, size_t solves) const {
    state.counters["median_centre_err_mm"] = centre_mm.empty() ? -1 : Median(centre_mm);
    state.counters["failures"] = failures;
    state.counters["inliers"] = solves > static_cast<size_t>(failures) ? inliers / (solves - failures) : 0;
  }
};

void BM_RealCorrespondences_OpenGV_LM(benchmark::State& state) {
  const RealCorrespondences* m = RealMatches();
  if (!m) return state.SkipWithError("no frames");
  const calib::Camera& camera = Real()->map.camera;
  AbsolutePoseOptions options;
  options.ransac_threshold_px = kThresholdPx;
  options.inlier_threshold_px = kThresholdPx;
  RealErrors errors;
  size_t i = 0;
  for (auto _ : state) {
    const size_t f = i++ % m->pixels.size();
    const AbsolutePoseResult r = EstimateAbsolutePose(camera, m->pixels[f], m->points[f], options);
    errors.Add(r.ok, r.pose, m->true_centre[f], Real()->map_to_mm, r.stats.inliers);
  }
  errors.Report(state, i);
  state.SetLabel(Real()->source);
}
BENCHMARK(BM_RealCorrespondences_OpenGV_LM)->Unit(benchmark::kMicrosecond);

void BM_RealCorrespondences_OpenCV_RansacRefineLM(benchmark::State& state) {
  const RealCorrespondences* m = RealMatches();
  if (!m) return state.SkipWithError("no frames");
  const calib::Camera& camera = Real()->map.camera;
  RealErrors errors;
  size_t i = 0;
  for (auto _ : state) {
    const size_t f = i++ % m->pixels.size();
    calib::Pose pose;
    int inliers = 0;
    const bool ok = OpenCvPose(camera, m->pixels[f], m->points[f], static_cast<int>(state.range(0)), &pose, &inliers);
    errors.Add(ok, pose, m->true_centre[f], Real()->map_to_mm, inliers);
  }
  errors.Report(state, i);
  state.SetLabel(std::string(OpenCvFlagName(static_cast<int>(state.range(0)))) + ", " + Real()->source);
}
BENCHMARK(BM_RealCorrespondences_OpenCV_RansacRefineLM)->Arg(cv::SOLVEPNP_P3P)->Arg(cv::SOLVEPNP_AP3P)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace arview::tracker

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  arview::KeepFreedHeapForReuse();  // as app/cli/main.cpp does, so that the figures are the app's
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* prefix) { return arg.substr(std::strlen(prefix)); };
    if (arg.rfind("--map=", 0) == 0) arview::tracker::g_map_dir = value("--map=");
    else if (arg.rfind("--recording=", 0) == 0) arview::tracker::g_recording_dir = value("--recording=");
    else if (arg.rfind("--frames=", 0) == 0) arview::tracker::g_frames_spec = value("--frames=");
    else rest.push_back(argv[i]);
  }
  if (arview::tracker::g_map_dir.empty() != arview::tracker::g_recording_dir.empty()) {
    std::cerr << "bench_tracker: --map and --recording go together\n";
    return 2;
  }
  int rest_argc = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_argc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(rest_argc, rest.data())) return 2;
  try {
    benchmark::RunSpecifiedBenchmarks();
  } catch (const std::exception& e) {
    std::cerr << "bench_tracker: " << e.what() << "\n";
    return 1;
  }
  benchmark::Shutdown();
  return 0;
}
