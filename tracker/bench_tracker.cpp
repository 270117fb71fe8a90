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
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstring>
#include <iostream>
#include <memory>
#include <string>

#include "mapping/map_file.h"
#include "recordings/recording.h"
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

void BM_PoseSolver_OpenGV_Ceres(benchmark::State& state) {
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
  state.SetLabel(MinimalSolverName(options.solver));
}
BENCHMARK(BM_PoseSolver_OpenGV_Ceres)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_PoseSolver_OpenCV_RansacRefineLM(benchmark::State& state) {
  const calib::Camera camera = testing::TestCamera();
  const cv::Mat K(camera.K()), dist = camera.DistCoeffs();
  const int flags = static_cast<int>(state.range(0));
  ErrorAccumulator errors;
  size_t i = 0;
  for (auto _ : state) {
    const auto& scene = Scenes()[i++ % kScenes];
    std::vector<cv::Point2d> image;
    std::vector<cv::Point3d> object;
    for (size_t j = 0; j < scene.pixels.size(); ++j) {
      image.emplace_back(scene.pixels[j].x(), scene.pixels[j].y());
      object.emplace_back(scene.points[j].x(), scene.points[j].y(), scene.points[j].z());
    }
    cv::Mat rvec, tvec;
    std::vector<int> inliers;
    bool ok = cv::solvePnPRansac(object, image, K, dist, rvec, tvec, false, 1000, static_cast<float>(kThresholdPx),
                                 0.999, inliers, flags);
    if (ok && inliers.size() >= 6) {
      std::vector<cv::Point2d> in_image;
      std::vector<cv::Point3d> in_object;
      for (int k : inliers) {
        in_image.push_back(image[k]);
        in_object.push_back(object[k]);
      }
      cv::solvePnPRefineLM(in_object, in_image, K, dist, rvec, tvec);
    } else {
      ok = false;
    }
    calib::Pose pose;
    if (ok) {
      cv::Mat R;
      cv::Rodrigues(rvec, R);
      Eigen::Matrix3d Re;
      Eigen::Vector3d te;
      cv::cv2eigen(R, Re);
      cv::cv2eigen(tvec, te);
      pose = calib::Pose::FromRt(Re, te);
    }
    errors.Add(ok, pose, scene.pose, static_cast<int>(inliers.size()));
  }
  errors.Report(state);
  state.SetLabel(flags == cv::SOLVEPNP_P3P ? "P3P" : flags == cv::SOLVEPNP_AP3P ? "AP3P" : "EPNP");
}
BENCHMARK(BM_PoseSolver_OpenCV_RansacRefineLM)
    ->Arg(cv::SOLVEPNP_P3P)
    ->Arg(cv::SOLVEPNP_AP3P)
    ->Arg(cv::SOLVEPNP_EPNP)
    ->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------------------------------------
// Real frames: a recording + its map, or renderings of a real photograph on a plane.

struct RealFrames {
  mapping::Map map;
  std::vector<cv::Mat> frames;  // in sequence order
  std::string source;
};

std::string g_map_dir, g_recording_dir, g_frames_spec;

std::unique_ptr<RealFrames> LoadRealFrames() {
  auto real = std::make_unique<RealFrames>();
  if (!g_map_dir.empty()) {
    real->map = mapping::LoadMap(g_map_dir);
    const recordings::Recording rec = recordings::LoadRecording(g_recording_dir);
    const std::vector<int> indices =
        recordings::ParseFrameSpec(g_frames_spec.empty() ? "0-" + std::to_string(rec.frames.size() - 1) : g_frames_spec,
                                   static_cast<int>(rec.frames.size()));
    for (int i : indices) real->frames.push_back(rec.ReadImage(i));
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
    real->frames.push_back(world.Render(LookAt({-0.15 + a, 0.05 * std::sin(3 * a), -0.8 - 0.1 * a}, {0.02, 0, 0})));
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

// One relocalization per frame: the tracker forgets its prior before each.
void BM_Relocalize(benchmark::State& state) {
  const RealFrames* real = Real();
  if (!real) return state.SkipWithError("no frames (opencv-doc missing, no --map)");
  TrackerOptions options;
  options.relocalization.features.max_features = static_cast<int>(state.range(0));
  Tracker tracker(real->map, options);
  size_t i = 0;
  int localized = 0;
  for (auto _ : state) {
    tracker.Reset();
    const FrameResult r = tracker.Track(real->frames[i % real->frames.size()], static_cast<double>(i));
    ++i;
    localized += r.status != TrackStatus::kLost;
  }
  state.counters["localized_ratio"] = static_cast<double>(localized) / state.iterations();
  state.SetLabel(real->source);
}
BENCHMARK(BM_Relocalize)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

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

}  // namespace
}  // namespace arview::tracker

int main(int argc, char** argv) {
  cv::setNumThreads(1);
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
