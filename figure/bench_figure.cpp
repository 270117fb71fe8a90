// bench_figure: what the built-in figure's morph targets cost a frame at 640x480 (Google
// Benchmark, real time, since llvmpipe rasterizes on its own threads).
//   BM_FigureFrame/weighted:<n>  anim update + GPU skinning (DQS) + draw with 4x MSAA + contact
//                                shadow + background upload + resolve + read-back of the figure
//                                from 1.2 m (the head about 100 px tall), with the first <n> of its
//                                ARKit targets weighted at 0.3 to 0.9 (0: the program without morphing);
//                                gaze:1 poses the eyes and lids toward the camera every frame
//                                (anim/gaze.h), gaze:0 leaves them at rest
// Compare weighted:8/gaze:1 (the face on) with weighted:0/gaze:0 (off) in one run: the difference
// is the face's cost a frame. Counter process_cpu_ms: the process's CPU a frame, all threads. Render's own
// morph cases (BM_ArFrameMorph, BM_ArFrameFace) are in bench_render; this one is here because
// render/ does not link figure/.

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
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

void BM_FigureFrame(benchmark::State& state) {
  RegisterBuiltinCharacters();
  static std::unique_ptr<render::OffscreenContext> context = render::OffscreenContext::Create();
  const bool gaze = state.range(1) != 0;
  const authoring::Scene scene = authoring::ParseScene(std::string("characters:\n  - asset: builtin:figure\n    gaze: {enabled: ") +
                                                           (gaze ? "true" : "false") + "}\n    keys: [{azimuth: 0, clip: Idle}]\n",
                                                       "bench.yaml");
  authoring::AnimatedCharacter figure(scene.characters[0]);
  const anim::Placement placement = scene.characters[0].placement();
  // 1.2 m in front of the eyes, looking back along -Z (camera y down: 180° about X).
  const Eigen::Vector3d camera_at(0, 1.635, 1.294);
  const calib::Pose pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond(0, 1, 0, 0), camera_at);
  const calib::Camera camera = calib::Camera::Pinhole(640, 480, 600, 600, 320, 240);
  render::ArRenderer renderer(*context, camera, render::ArOptions{});
  renderer.AddCharacter(figure.character(), placement);
  const cv::Mat background(480, 640, CV_8UC3, cv::Scalar(90, 100, 110));
  std::vector<float> weights(figure.character().skeleton.morph_target_count(), 0.f);
  for (int k = 0; k < std::min<int>(static_cast<int>(state.range(0)), static_cast<int>(weights.size())); ++k)
    weights[k] = 0.3f + 0.6f * (k % 7) / 6;
  double time = 0;
  auto frame = [&] {
    anim::AnimatorFrame f = figure.Update(placement.ViewpointFromCamera(camera_at), time, placement.MapToModel(camera_at));
    f.morph_weights = weights;
    const anim::AnimatorFrame* frames[] = {&f};
    return renderer.Render(background, pose, frames);
  };
  for (int i = 0; i < 3; ++i) frame();  // llvmpipe compiles each new pipeline state at its first draw
  const std::clock_t cpu_start = std::clock();  // the process's CPU, llvmpipe's threads included
  for (auto _ : state) {
    const cv::Mat image = frame();
    benchmark::DoNotOptimize(image.data);
    time += 1.0 / 30;
  }
  // Steadier than the real time on a loaded machine: what a frame costs the cores.
  state.counters["process_cpu_ms"] =
      1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / std::max<double>(1.0, state.iterations());
}

BENCHMARK(BM_FigureFrame)
    ->Args({0, 0})
    ->Args({8, 0})
    ->Args({8, 1})
    ->ArgNames({"weighted", "gaze"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace arview::figure

BENCHMARK_MAIN();
