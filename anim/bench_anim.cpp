// bench_anim: the per-frame costs of view-adaptive blending (Google Benchmark, one thread).
//   BM_Blend/<method>/<K>        blend K poses of 27 joints (DLB or DIB, p = 0.001)
//   BM_SampleBlend/<method>/<K>  sample K clips of 27 joints at one time, then blend
//   BM_SampleNlerpBlend/...      the same with nlerp sampling (SamplingJob::nlerp)
//   BM_Skinning/<method>         CPU skinning of 25 000 vertices, 4 influences, 27 joints
//   BM_FoxUpdate/<method>        AnimatedCharacter::Update on the Fox with 8 look-at keys
//   BM_ScheduleUpdate/<dib>      Animator::Update, BCN_Epileptic (54 joints), a four-action schedule
//   BM_ScheduleUpdateGesture/<dib>  the same with the gesture a generated point gesture (IK)
//   BM_FourActionSchedule3600    BM_ScheduleUpdateGesture/dib:0, exactly 3600 updates (callgrind)
//   BM_IdleLayerSample/<balance> the idle layer alone, without (0) or with (1) the balance shifts
//                                under its variations, on the constructed 13-joint standing person
//   BM_MorphWeights/<targets>    Animator::Update of tests/support/face_schedule.h: three clips
//                                keying <targets> morph target weights (0: none), sampled and
//                                blended, and a face layer's write
//   BM_GazeApply                 Gaze::Apply alone on builtin:figure (eyes, lids, the saccade and
//                                blink process), the viewer moving in front
//   BM_FigureUpdate/<gaze>       Animator::Update of builtin:figure with 8 look-at keys, without (0)
//                                or with (1) gaze: what the eyes add to a frame
// The 27-joint skeleton and its clips are synthetic and seeded (the paper's character had 27
// joints); the Fox benchmark uses the real asset from ../shared/data when it is there.

#include "anim_authoring/animator_builder.h"
#include "anim_authoring/character_builder.h"
#include "figure/humanoid.h"
#include "anim/pose.h"
#include "anim/animator.h"
#include "anim_authoring/scene.h"
#include "tests/support/face_schedule.h"
#include "tests/support/four_action_schedule.h"
#include "tests/support/standing_recording.h"
#include "tests/support/test_data.h"

#include <benchmark/benchmark.h>

#include <random>

namespace arview::anim {
namespace {

constexpr int kJoints = 27;

Skeleton MakeSkeleton(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Skeleton sk;
  for (int j = 0; j < kJoints; ++j) {
    sk.names.push_back("j" + std::to_string(j));
    sk.parents.push_back(j == 0 ? -1 : std::uniform_int_distribution<int>(std::max(0, j - 4), j - 1)(rng));
    Transform t;
    t.translation = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.2;
    t.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
    sk.rest.push_back(t);
    sk.inverse_bind.push_back(Eigen::Matrix4d::Identity());
  }
  return sk;
}

// A 2-second clip at 30 keys/s: rotation on every joint, translation on the root.
Clip MakeClip(std::mt19937& rng, const Skeleton& sk) {
  std::uniform_real_distribution<double> u(-1, 1);
  Clip c;
  c.duration = 2.0;
  c.tracks.resize(sk.size());
  for (int j = 0; j < sk.size(); ++j)
    for (int k = 0; k <= 60; ++k) {
      const double t = k / 30.0;
      const Eigen::Quaterniond q(Eigen::AngleAxisd(0.5 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
      c.tracks[j].rotation.push_back({t, sk.rest[j].rotation * q});
      if (j == 0) c.tracks[j].translation.push_back({t, Eigen::Vector3d(u(rng), u(rng), u(rng))});
    }
  return c;
}

struct Setup {
  Skeleton skeleton;
  std::vector<Clip> clips;
  std::vector<LocalPose> poses;
  std::vector<const LocalPose*> ptrs;
  std::vector<double> weights;
  LocalPose out;

  explicit Setup(int keys) {
    std::mt19937 rng(42);
    skeleton = MakeSkeleton(rng);
    for (int k = 0; k < keys; ++k) {
      clips.push_back(MakeClip(rng, skeleton));
      poses.emplace_back(skeleton.size());
      MustRun(SamplingJob{&skeleton, &clips.back(), 0.77, true, &poses.back()}, "bench setup");
    }
    for (auto& p : poses) ptrs.push_back(&p);
    // Weights from Eq. 2 for keys around the horizon and a viewpoint between two of them.
    std::vector<Eigen::Vector3d> dirs;
    for (int k = 0; k < keys; ++k) dirs.push_back(DirectionFromAzimuthElevation(360.0 * k / keys, 0));
    ViewSphere sphere(dirs);
    weights.resize(keys);
    sphere.Weights(DirectionFromAzimuthElevation(360.0 / keys * 0.4, 15), weights);
    out.Resize(skeleton.size());
  }
};

BlendingJob MakeJob(Setup& s, BlendMethod method) {
  BlendingJob job;
  job.inputs = s.ptrs;
  job.weights = s.weights;
  job.method = method;
  job.output = &s.out;
  return job;
}

void BM_Blend(benchmark::State& state) {
  const auto method = static_cast<BlendMethod>(state.range(0));
  Setup s(static_cast<int>(state.range(1)));
  bool converged = true;
  int iterations = 0;
  BlendingJob job = MakeJob(s, method);
  job.converged = &converged;
  job.max_iterations = &iterations;
  for (auto _ : state) {
    if (!job.Run()) return state.SkipWithError("blending job refused its inputs");
    benchmark::DoNotOptimize(s.out.rigid.data());
  }
  state.counters["max_iter"] = iterations;
  state.counters["converged"] = converged;
  state.SetLabel(method == BlendMethod::kDlb ? "DLB" : "DIB");
}

void SampleBlend(benchmark::State& state, bool nlerp) {
  const auto method = static_cast<BlendMethod>(state.range(0));
  Setup s(static_cast<int>(state.range(1)));
  const BlendingJob job = MakeJob(s, method);
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 60;
    bool ok = job.Validate();
    for (std::size_t k = 0; k < s.clips.size(); ++k)
      ok = SamplingJob{&s.skeleton, &s.clips[k], t, true, &s.poses[k], nlerp}.Run() && ok;
    if (!ok || !job.Run()) return state.SkipWithError("a job refused its inputs");
    benchmark::DoNotOptimize(s.out.rigid.data());
  }
  state.SetLabel(method == BlendMethod::kDlb ? "DLB" : "DIB");
}

void BlendArgs(benchmark::internal::Benchmark* b) {
  for (int m : {0, 1})
    for (int k : {2, 4, 8, 16}) b->Args({m, k});
  b->ArgNames({"method", "keys"});
}
void BM_SampleBlend(benchmark::State& state) { SampleBlend(state, false); }
void BM_SampleNlerpBlend(benchmark::State& state) { SampleBlend(state, true); }
BENCHMARK(BM_Blend)->Apply(BlendArgs);
BENCHMARK(BM_SampleBlend)->Apply(BlendArgs);
BENCHMARK(BM_SampleNlerpBlend)->Apply(BlendArgs);

void BM_Skinning(benchmark::State& state) {
  const auto method = static_cast<SkinningMethod>(state.range(0));
  std::mt19937 rng(7);
  const Skeleton sk = MakeSkeleton(rng);
  const Clip clip = MakeClip(rng, sk);
  Mesh mesh;
  std::uniform_real_distribution<float> u(-1, 1);
  std::uniform_int_distribution<int> joint(0, kJoints - 1);
  for (int v = 0; v < 25000; ++v) {
    mesh.positions.emplace_back(u(rng), u(rng), u(rng));
    mesh.normals.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized());
    std::array<std::uint16_t, 4> js;
    Eigen::Vector4f ws;
    for (int i = 0; i < 4; ++i) {
      js[i] = static_cast<std::uint16_t>(joint(rng));
      ws[i] = 0.05f + std::abs(u(rng));
    }
    mesh.joints.push_back(js);
    mesh.weights.push_back(ws / ws.sum());
  }
  LocalPose pose(sk.size());
  MustRun(SamplingJob{&sk, &clip, 0.5, true, &pose}, "bench setup");
  std::vector<Eigen::Matrix4d> model(sk.size());
  MustRun(LocalToModelJob{&sk, &pose, model}, "bench setup");
  std::vector<Eigen::Matrix4f> skin(sk.size());
  std::vector<DualQuatf> dq(sk.size());
  MustRun(SkinningMatricesJob{&sk, model, skin, dq}, "bench setup");
  std::vector<Eigen::Vector3f> pos(mesh.positions.size()), nrm(mesh.positions.size());
  const SkinningJob job{&mesh, method, skin, dq, pos, nrm};
  for (auto _ : state) {
    if (!job.Run()) return state.SkipWithError("skinning job refused its inputs");
    benchmark::DoNotOptimize(pos.data());
  }
  state.SetLabel(method == SkinningMethod::kLinear ? "LBS" : "DQS");
  state.SetItemsProcessed(state.iterations() * 25000);
}
BENCHMARK(BM_Skinning)->Arg(0)->Arg(1)->ArgName("method");

void BM_FoxUpdate(benchmark::State& state) {
  const auto fox = testing::SharedData("characters/Fox/glTF-Binary/Fox.glb");
  if (!std::filesystem::exists(fox)) {
    state.SkipWithError(("needs " + fox.string()).c_str());
    return;
  }
  std::string text = "characters:\n  - asset: " + fox.string() + "\n    blend: {method: " +
                     (state.range(0) ? "dib" : "dlb") + "}\n    sampling: " + (state.range(1) ? "nlerp" : "slerp") +
                     "\n    keys:\n";
  for (int k = 0; k < 8; ++k) text += "      - azimuth: " + std::to_string(45 * k) + "\n        generate: lookat\n";
  authoring::AnimatedCharacter ch(authoring::ParseScene(text, "bench.yaml").characters[0]);
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 60;
    const AnimatorFrame& out = ch.Update(DirectionFromAzimuthElevation(100 * t, 0), t);
    benchmark::DoNotOptimize(out.skinning_matrices.data());
  }
  state.SetLabel(std::string(state.range(0) ? "DIB" : "DLB") + (state.range(1) ? " nlerp" : " slerp"));
}
BENCHMARK(BM_FoxUpdate)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->ArgNames({"method", "nlerp"});

// One Animator::Update of the 54-joint BCN_Epileptic with issue 13's four-action schedule
// (tests/support/four_action_schedule.h): the idle synthesizer learned from its own clip
// underneath, the 8-key look-at view-adaptive blend on top, a torso-masked gesture fading in
// and out (cosine, re-timed as it ends) and a clip masked to the left arm; weights, sampling,
// the layered frame blender, local-to-model and skinning matrices included.
//   BM_ScheduleUpdate         the gesture is the character's clip mirrored
//   BM_ScheduleUpdateGesture  the gesture is a generated point gesture (two-bone IK)
void ScheduleUpdate(benchmark::State& state, testing::FourActionSchedule::Gesture gesture) {
  if (!std::filesystem::exists(testing::kBcnEpileptic)) {
    state.SkipWithError((std::string("needs ") + testing::kBcnEpileptic + " (Debian package assimp-testmodels)").c_str());
    return;
  }
  testing::FourActionSchedule schedule(gesture, state.range(0) != 0);
  for (auto _ : state) {
    const AnimatorFrame& f = schedule.Step(1.0 / 60);
    benchmark::DoNotOptimize(f.skinning_matrices.data());
  }
  state.SetLabel(std::string(state.range(0) ? "DIB" : "DLB") + ", 54 joints, 4 actions" +
                 (gesture == testing::FourActionSchedule::Gesture::kPoint ? ", point gesture" : ""));
}
void BM_ScheduleUpdate(benchmark::State& state) { ScheduleUpdate(state, testing::FourActionSchedule::Gesture::kMirroredClip); }
void BM_ScheduleUpdateGesture(benchmark::State& state) { ScheduleUpdate(state, testing::FourActionSchedule::Gesture::kPoint); }
BENCHMARK(BM_ScheduleUpdate)->Arg(0)->Arg(1)->ArgName("dib");
BENCHMARK(BM_ScheduleUpdateGesture)->Arg(0)->Arg(1)->ArgName("dib");
// BM_ScheduleUpdateGesture/dib:0 for exactly 3600 updates (60 s at 60 Hz) in one run: the same
// stretch of the stream every time, so that instruction counts repeat (a timed run's iteration
// count, hence which segments the idle synthesizer draws and checks, depends on the timing):
//   valgrind --tool=callgrind --toggle-collect='arview::anim::Animator::Update*' bench_anim --benchmark_filter=BM_FourActionSchedule3600
BENCHMARK(BM_ScheduleUpdateGesture)->Name("BM_FourActionSchedule3600")->Arg(0)->ArgName("dib")->Iterations(3600);

// The idle layer's own cost per frame at 60 Hz: the idle synthesizer alone (balance:0), or the
// balance-shift layer with the synthesizer's variations on top (balance:1, what a scene with
// `idle.balance:` plays), both learned from the constructed recording of a standing person
// (tests/support/standing_recording.h, 13 joints: no recording on this machine holds a balance
// shift to learn from).
void BM_IdleLayerSample(benchmark::State& state) {
  const auto standing = testing::LearnFromStanding(testing::LongStanding());
  const auto sk = standing->skeleton();
  auto idle = std::make_shared<IdleSynthesizer>(sk, std::make_shared<const IdleModel>(standing->idle), 1);
  BlendablePtr layer = idle;
  if (state.range(0))
    layer = std::make_shared<BalanceShifter>(sk, std::make_shared<const BalanceModel>(*standing->balance), 1, idle);
  LocalPose pose(sk->size());
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 60;
    if (!layer->Sample(t, {}, pose)) state.SkipWithError("the layer did not sample");
    benchmark::DoNotOptimize(pose.rigid.data());
  }
  state.SetLabel(state.range(0) ? "balance shifts + idle variations, 13 joints" : "idle variations, 13 joints");
}
BENCHMARK(BM_IdleLayerSample)->Arg(0)->Arg(1)->ArgName("balance");

void BM_MorphWeights(benchmark::State& state) {
  testing::FaceSchedule face(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(face.Step(1.0 / 60).morph_weights.data());
}
BENCHMARK(BM_MorphWeights)->Arg(0)->Arg(16)->Arg(52)->Arg(128)->ArgName("targets");
std::string FigureScene(bool gaze) {
  std::string text = std::string("characters:\n  - asset: builtin:figure\n    lookat: {base_clip: Idle}\n    gaze: {enabled: ") +
                     (gaze ? "true" : "false") + ", mode: talking}\n    keys:\n";
  for (int k = 0; k < 8; ++k) text += "      - azimuth: " + std::to_string(45 * k) + "\n        generate: lookat\n";
  return text;
}

// The viewer 1.2 m away at eye height, going round the front (±40°) every 10 s.
FrameInputs ViewerInFront(double t) {
  const double azimuth = 40 * std::sin(2 * M_PI * t / 10) * M_PI / 180;
  const Eigen::Vector3d camera(1.2 * std::sin(azimuth), 1.64, 1.2 * std::cos(azimuth));
  FrameInputs in;
  in.viewpoint = camera.normalized();
  in.distance = 1.2;
  in.viewer = camera;
  return in;
}

void BM_GazeApply(benchmark::State& state) {
  const Character figure = figure::MakeHumanoid();
  const Skeleton& sk = figure.skeleton;
  GazeOptions options;
  options.mode = GazeMode::kTalking;
  Gaze gaze(sk, FindGazeRig(sk), options);
  LocalPose pose = LocalPose::Rest(sk);
  std::vector<Eigen::Matrix4d> model(sk.size());
  MustRun(LocalToModelJob{&sk, &pose, model}, "bench");
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 60;
    gaze.Apply(t, ViewerInFront(t).viewer, model, pose);
    benchmark::DoNotOptimize(pose.rigid.data());
  }
  state.SetLabel("builtin:figure, 2 eyes and 4 lids, talking");
}
BENCHMARK(BM_GazeApply);

void BM_FigureUpdate(benchmark::State& state) {
  figure::RegisterBuiltinCharacters();
  authoring::AnimatedCharacter ch(authoring::ParseScene(FigureScene(state.range(0) != 0), "bench.yaml").characters[0]);
  const std::unique_ptr<Animator> animator = authoring::BuildAnimator(ch);
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 60;
    const AnimatorFrame& f = animator->Update(t, ViewerInFront(t));
    benchmark::DoNotOptimize(f.skinning_matrices.data());
  }
  state.SetLabel(std::string("builtin:figure, 38 joints, 8 look-at keys, DLB") + (state.range(0) ? ", gaze" : ""));
}
BENCHMARK(BM_FigureUpdate)->Arg(0)->Arg(1)->ArgName("gaze");

}  // namespace
}  // namespace arview::anim

BENCHMARK_MAIN();
