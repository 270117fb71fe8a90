// bench_figure: what the built-in figure's morph targets cost a frame at 640x480 (Google
// Benchmark, real time, since llvmpipe rasterizes on its own threads).
//   BM_FigureFrame/weighted:<n>  anim update + GPU skinning (DQS) + draw with 4x MSAA + contact
//                                shadow + background upload + resolve + read-back of the figure
//                                from 1.2 m (the head about 100 px tall), with the first <n> of its
//                                ARKit targets weighted at 0.3 to 0.9 (0: the program without morphing);
//                                gaze:1 poses the eyes and lids toward the camera every frame
//                                (anim/gaze.h), gaze:0 leaves them at rest; cpu_morph:1 adds the
//                                weighted deltas on the CPU (the renderer's default for a face's
//                                few deltas), cpu_morph:0 in the vertex shader
// Compare weighted:8/gaze:1 (the face on) with weighted:0/gaze:0 (off) in one run: the difference
// is the face's cost a frame; weighted:8/gaze:1/cpu_morph:0 is the same face through the shader. Counter process_cpu_ms: the process's CPU a frame, all threads. Render's own
// morph cases (BM_ArFrameMorph, BM_ArFrameFace) are in bench_render; this one is here because
// render/ does not link figure/.
//   BM_FigureFaceCost/weighted:8/gaze:1/cpu_morph:<0|1>  the face on (8 targets weighted, gaze;
//                                the other cases one of the two) and off, frame by frame in
//                                one loop (the order swapped every other frame): counters
//                                face_real_ms and face_cpu_ms are the mean of the per-pair
//                                differences (real time; the process's CPU), *_se their standard
//                                errors. Pairing cancels the machine's drift, which makes the
//                                separate cases above differ by ±0.3 ms from run to run.

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <ctime>
#include <memory>
#include <string>

#include "anim_authoring/character_builder.h"
#include "anim_authoring/scene.h"
#include "figure/humanoid.h"
#include "render/ar_renderer.h"
#include "render/offscreen.h"

namespace arview::figure {
namespace {

render::OffscreenContext& Context() {
  static std::unique_ptr<render::OffscreenContext> context = render::OffscreenContext::Create();
  return *context;
}

// The built-in figure from 1.2 m in front of its eyes (looking back along -Z; camera y down:
// 180° about X), its first `weighted` targets at 0.3 to 0.9, gaze on or off.
class FigureView {
 public:
  FigureView(int weighted, bool gaze, bool cpu_morph)
      : scene_(authoring::ParseScene(std::string("characters:\n  - asset: builtin:figure\n    gaze: {enabled: ") +
                                         (gaze ? "true" : "false") + "}\n    keys: [{azimuth: 0, clip: Idle}]\n",
                                     "bench.yaml")),
        figure_(scene_.characters[0]),
        placement_(scene_.characters[0].placement()),
        renderer_(Context(), kCamera, Options(cpu_morph)),
        weights_(figure_.character().skeleton.morph_target_count(), 0.f) {
    renderer_.AddCharacter(figure_.character(), placement_);
    for (int k = 0; k < std::min<int>(weighted, static_cast<int>(weights_.size())); ++k)
      weights_[k] = 0.3f + 0.6f * (k % 7) / 6;
    for (int i = 0; i < 3; ++i) Frame();  // llvmpipe compiles each new pipeline state at its first draw
  }

  cv::Mat Frame() { return Frame(*this); }
  // Draws with this view's renderer the frame of `animated`'s figure and weights (the same
  // built-in figure, maybe another face).
  cv::Mat Frame(FigureView& animated) {
    anim::AnimatorFrame f = animated.figure_.Update(placement_.ViewpointFromCamera(kCameraAt), animated.time_,
                                                    placement_.MapToModel(kCameraAt));
    f.morph_weights = animated.weights_;
    const anim::AnimatorFrame* frames[] = {&f};
    animated.time_ += 1.0 / 30;
    return renderer_.Render(background_, kPose, frames);
  }

 private:
  static render::ArOptions Options(bool cpu_morph) {
    render::ArOptions options;
    options.cpu_morph_max_deltas = cpu_morph ? render::CharacterRenderer::kDefaultCpuMorphMaxDeltas : 0;
    return options;
  }
  inline static const Eigen::Vector3d kCameraAt{0, 1.635, 1.294};
  inline static const calib::Pose kPose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond(0, 1, 0, 0), kCameraAt);
  inline static const calib::Camera kCamera = calib::Camera::Pinhole(640, 480, 600, 600, 320, 240);
  authoring::Scene scene_;
  authoring::AnimatedCharacter figure_;
  anim::Placement placement_;
  render::ArRenderer renderer_;
  std::vector<float> weights_;
  cv::Mat background_{480, 640, CV_8UC3, cv::Scalar(90, 100, 110)};
  double time_ = 0;
};

void BM_FigureFrame(benchmark::State& state) {
  RegisterBuiltinCharacters();
  FigureView view(static_cast<int>(state.range(0)), state.range(1) != 0, state.range(2) != 0);
  const std::clock_t cpu_start = std::clock();  // the process's CPU, llvmpipe's threads included
  for (auto _ : state) {
    const cv::Mat image = view.Frame();
    benchmark::DoNotOptimize(image.data);
  }
  // Steadier than the real time on a loaded machine: what a frame costs the cores.
  state.counters["process_cpu_ms"] =
      1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / std::max<double>(1.0, state.iterations());
}

BENCHMARK(BM_FigureFrame)
    ->Args({0, 0, 1})
    ->Args({8, 0, 1})
    ->Args({8, 1, 1})
    ->Args({8, 1, 0})
    ->ArgNames({"weighted", "gaze", "cpu_morph"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Running mean and standard error of the per-pair differences.
struct PairedDifference {
  double sum = 0, sum_squares = 0;
  int n = 0;
  void Add(double d) {
    sum += d;
    sum_squares += d * d;
    ++n;
  }
  double Mean() const { return n ? sum / n : 0; }
  double StandardError() const {
    if (n < 2) return 0;
    const double variance = (sum_squares - sum * sum / n) / (n - 1);
    return std::sqrt(std::max(variance, 0.0) / n);
  }
};

void BM_FigureFaceCost(benchmark::State& state) {
  RegisterBuiltinCharacters();
  // One renderer draws both: the face on (the gazing figure's frame, the first `weighted` targets
  // weighted) and off (the same figure without gaze, no target weighted), so that the two differ
  // only in what is drawn. (Two renderers, one for each, differed by 0.1-0.3 ms with the same
  // face on both: where their buffers happen to lie.)
  FigureView on(static_cast<int>(state.range(0)), state.range(1) != 0, state.range(2) != 0);
  FigureView off(0, false, state.range(2) != 0);
  PairedDifference real_ms, cpu_ms;
  const auto timed = [&](FigureView& frames_of, double& real, double& cpu) {
    const auto wall0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    const cv::Mat image = on.Frame(frames_of);
    benchmark::DoNotOptimize(image.data);
    cpu = 1e3 * static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    real = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  };
  bool on_first = true;
  for (auto _ : state) {
    double on_real = 0, on_cpu = 0, off_real = 0, off_cpu = 0;
    if (on_first) {
      timed(on, on_real, on_cpu);
      timed(off, off_real, off_cpu);
    } else {
      timed(off, off_real, off_cpu);
      timed(on, on_real, on_cpu);
    }
    on_first = !on_first;
    real_ms.Add(on_real - off_real);
    cpu_ms.Add(on_cpu - off_cpu);
  }
  state.counters["face_real_ms"] = real_ms.Mean();
  state.counters["face_real_ms_se"] = real_ms.StandardError();
  state.counters["face_cpu_ms"] = cpu_ms.Mean();
  state.counters["face_cpu_ms_se"] = cpu_ms.StandardError();
}

BENCHMARK(BM_FigureFaceCost)
    ->Args({8, 1, 1})
    ->Args({8, 1, 0})
    ->Args({8, 0, 1})
    ->Args({0, 1, 1})
    ->Args({0, 0, 1})
    ->ArgNames({"weighted", "gaze", "cpu_morph"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace arview::figure

BENCHMARK_MAIN();
