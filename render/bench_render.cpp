// bench_render: per-frame cost of the augmented frame at 640x480 (Google Benchmark, real time,
// since llvmpipe rasterizes on its own threads).
//   BM_ArFrame/<character>       anim update (sample + blend + skinning transforms) + GPU
//                                skinning (DQS) + draw with 4x MSAA + contact shadow + background
//                                upload + resolve + read-back: Fox, CesiumMan, and a synthetic
//                                25 000-triangle skinned tube (10 joints, 2 influences)
//   BM_ArFrameNoAa/<character>   the same without antialiasing
//   BM_ArFrameLit[NoAa]/<c>     the same with the room's light (issue 14): SH through self-shadowed
//                                PRT, exposure follower, cast shadow, depth-only occluder proxy;
//                                counter prt_precompute_s: the PRT ray casting at AddCharacter
//   BM_ArFrameLit1080p/tube25k   the lit 25k-triangle frame at 1920x1080 (same field of view)
//   BM_Readback1080p/<way>       clear, resolve and read back a 4x MSAA 1920x1080 target: direct
//                                (glReadPixels) or pixel_buffer (a fence, then a map)
//   BM_UndistortBackground       cv::remap of a 640x480 frame with precomputed maps (the cost of
//                                lens distortion in the AR path)
//   BM_SynthRoomFrame            one frame of `arview synth room` (render + read-back, no PNG),
//                                at poses spread over the default 10 s path
//   BM_ArFrameMorph/weighted:<n> BM_ArFrame of the 25k-triangle tube with 52 morph targets that
//                                each move every vertex, <n> of them weighted (0: the program
//                                without morphing)
//   BM_ArFrameFace/weighted:<n>  the same tube with a 4000-triangle head mesh on top that the 52
//                                targets move alone (a face of its own)
//   BM_ArFrameFences/<c>_<way>   BM_ArFrame with the read-backs' scene fences held (hold: the fix
//                                of issue 57's crash, render::SceneFences), a sync object made and
//                                deleted at once (release_at_once), or none (none: as before the
//                                fix); compare with --benchmark_enable_random_interleaving
//   BM_SmallReadbackFences/<way> the same three ways on a cleared 4x MSAA 640x480 target's
//                                64x64 read-back alone (the fixed cost a read-back)
// llvmpipe's thread count is fixed per process: run once per count,
//   bench_render --gl_threads=1    and    bench_render --gl_threads=2
// (also --gl=auto|egl-device|egl|osmesa, and --gl_device=N; ARVIEW_GL_DEVICE is honoured). Characters come from ../shared/data; missing ones are skipped.

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <sys/resource.h>

#include <cstring>
#include <map>

#include "anim/morph.h"
#include "anim_authoring/character_builder.h"
#include "anim_authoring/import.h"
#include "anim_authoring/scene.h"
#include "base/heap_reuse.h"
#include "render/ar_renderer.h"
#include "render/scene_fence_policy.h"
#include "synth/synth_room.h"
#include "tests/support/test_data.h"

namespace arview::render {
using namespace arview::room;  // the room's light and proxy, tested here with the renderer
using namespace arview::synth;  // the rendered room the light is measured in
namespace {

OffscreenOptions g_gl;  // auto, 1 thread unless the command line says otherwise

// CPU time of the whole process (all llvmpipe threads included), seconds: on a shared machine
// this is steadier than wall time and shows what a frame costs the cores that tracking shares.
double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

void CountProcessCpu(benchmark::State& state, double cpu_start) {
  state.counters["process_cpu_ms"] = 1e3 * (ProcessCpuSeconds() - cpu_start) / std::max<double>(1.0, state.iterations());
}

OffscreenContext& Context() {
  static std::unique_ptr<OffscreenContext> context = OffscreenContext::Create(g_gl);
  return *context;
}

// 640x480 by default; another size keeps the horizontal field of view (1920x1080: fx 1575).
calib::Camera BenchCamera(cv::Size size = {640, 480}) {
  const double f = 525.0 * size.width / 640;
  return calib::Camera::Pinhole(size.width, size.height, f, f, 0.5 * size.width - 0.5, 0.5 * size.height - 0.5);
}

const cv::Size k1080p(1920, 1080);

// A standing tube of `rings` x `segments` vertices bound to a chain of joints along its axis
// (model space: y up, 1.6 m tall), with a clip that bends it back and forth.
std::shared_ptr<const anim::Character> MakeTube(int triangles) {
  constexpr int kSegments = 50, kJoints = 10;
  const int rings = triangles / (2 * kSegments) + 1;
  constexpr double kHeight = 1.6, kRadius = 0.18;
  anim::Character c;
  c.source = "synthetic tube";
  for (int j = 0; j < kJoints; ++j) {
    c.skeleton.names.push_back("j" + std::to_string(j));
    c.skeleton.parents.push_back(j - 1);
    anim::Transform t;
    t.translation = Eigen::Vector3d(0, j == 0 ? 0 : kHeight / (kJoints - 1), 0);
    c.skeleton.rest.push_back(t);
    Eigen::Matrix4d inverse_bind = Eigen::Matrix4d::Identity();
    inverse_bind(1, 3) = -kHeight * j / (kJoints - 1);
    c.skeleton.inverse_bind.push_back(inverse_bind);
  }
  anim::Clip clip;
  clip.name = "Bend";
  clip.duration = 2.0;
  clip.tracks.resize(kJoints);
  for (int j = 1; j < kJoints; ++j)
    for (int k = 0; k <= 20; ++k) {
      const double t = k * 0.1;
      clip.tracks[j].rotation.push_back({t, Eigen::Quaterniond(Eigen::AngleAxisd(0.12 * std::sin(M_PI * t + 0.3 * j), Eigen::Vector3d::UnitZ()))});
    }
  c.clips.push_back(clip);
  anim::Mesh mesh;
  mesh.name = "tube";
  for (int r = 0; r < rings; ++r) {
    const double y = kHeight * r / (rings - 1);
    const double joint_pos = y / kHeight * (kJoints - 1);
    const int j0 = std::min(static_cast<int>(joint_pos), kJoints - 2);
    const float w1 = static_cast<float>(joint_pos - j0);
    for (int s = 0; s < kSegments; ++s) {
      const double a = 2 * M_PI * s / kSegments;
      mesh.positions.emplace_back(kRadius * std::cos(a), y, kRadius * std::sin(a));
      mesh.normals.emplace_back(std::cos(a), 0, std::sin(a));
      mesh.uvs.emplace_back(static_cast<float>(s) / kSegments, static_cast<float>(y / kHeight));
      mesh.joints.push_back({static_cast<std::uint16_t>(j0), static_cast<std::uint16_t>(j0 + 1), 0, 0});
      mesh.weights.emplace_back(1 - w1, w1, 0, 0);
    }
  }
  for (int r = 0; r + 1 < rings; ++r)
    for (int s = 0; s < kSegments; ++s) {
      const std::uint32_t a = r * kSegments + s, b = r * kSegments + (s + 1) % kSegments;
      mesh.indices.insert(mesh.indices.end(), {a, b, a + kSegments, b, b + kSegments, a + kSegments});
    }
  mesh.material = 0;
  c.materials.push_back({"tube", Eigen::Vector4f(0.3f, 0.6f, 0.9f, 1.f), -1});
  c.meshes.push_back(std::move(mesh));
  return std::make_shared<const anim::Character>(std::move(c));
}

// The tube with 52 morph targets on mesh `morphed`, each moving every vertex of it (the most a
// target can cost): along its normal, by up to 2 cm, in a pattern of its own. With a head, the
// targets move a second mesh alone: a 4000-triangle tube 0.24 m tall on top, bound to the top
// joint (a face of its own, as a character's head mesh).
std::shared_ptr<const anim::Character> MakeMorphTube(bool head) {
  anim::Character c = *MakeTube(25000);
  if (head) {
    anim::Mesh face = MakeTube(4000)->meshes[0];
    for (Eigen::Vector3f& p : face.positions) p = 0.15f * p + Eigen::Vector3f(0, 1.6f, 0);
    for (auto& j : face.joints) j = {9, 0, 0, 0};
    for (auto& w : face.weights) w = Eigen::Vector4f(1, 0, 0, 0);
    c.meshes.push_back(face);
  }
  const int morphed = head ? 1 : 0;
  const anim::Mesh& mesh = c.meshes[morphed];
  for (int k = 0; k < 52; ++k) {
    std::vector<Eigen::Vector3f> positions(mesh.positions.size()), normals(mesh.positions.size());
    for (size_t v = 0; v < positions.size(); ++v) {
      const float s = 0.02f * static_cast<float>(std::sin(0.37 * k + 0.013 * static_cast<double>(v)));
      positions[v] = s * mesh.normals[v];
      normals[v] = Eigen::Vector3f(0, 0.1f * s, 0);
    }
    anim::AddMorphTarget(c, "target" + std::to_string(k), morphed, positions, normals);
  }
  return std::make_shared<const anim::Character>(std::move(c));
}

struct Subject {
  std::shared_ptr<const anim::Character> character;
  authoring::CharacterSpec spec;
  std::unique_ptr<authoring::AnimatedCharacter> animated;
  calib::Pose camera_pose;
};

// Anchored at the origin of a z-up map, model y up; the camera 2.5 m away, 1.2 m up.
std::unique_ptr<Subject> MakeSubject(std::shared_ptr<const anim::Character> character, double scale) {
  auto s = std::make_unique<Subject>();
  s->character = std::move(character);
  s->spec.name = s->character->source;
  s->spec.scale = scale;
  s->spec.anchor.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX());
  authoring::KeySpec key;
  key.clip = s->character->clips.empty() ? "" : s->character->clips[0].name;
  key.source = s->character->clips.empty() ? authoring::KeySpec::Source::kRestPose : authoring::KeySpec::Source::kClip;
  s->spec.keys.push_back(key);
  s->animated = std::make_unique<authoring::AnimatedCharacter>(s->character, s->spec);
  const Eigen::Vector3d eye(0.8, -2.4, 1.2), target(0, 0, 0.6);
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r_wc;
  r_wc << right, forward.cross(right), forward;
  s->camera_pose = calib::Pose::FromCameraToWorld(Eigen::Quaterniond(r_wc), eye);
  return s;
}

Subject* GetSubject(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Subject>> cache;
  if (auto it = cache.find(name); it != cache.end()) return it->second.get();
  std::unique_ptr<Subject> subject;
  if (name == "tube25k") {
    subject = MakeSubject(MakeTube(25000), 1.0);
  } else if (name == "tube25k_morph52" || name == "tube25k_face52") {
    subject = MakeSubject(MakeMorphTube(name == "tube25k_face52"), 1.0);
  } else {
    const auto path = name == "Fox" ? arview::testing::SharedData("characters/Fox/glTF-Binary/Fox.glb")
                                    : arview::testing::SharedData("characters/CesiumMan.glb");
    if (!std::filesystem::exists(path)) return nullptr;
    subject = MakeSubject(std::make_shared<const anim::Character>(authoring::LoadCharacter(path)), name == "Fox" ? 0.01 : 1.0);
  }
  return (cache[name] = std::move(subject)).get();
}

cv::Mat Background(cv::Size size = {640, 480}) {
  cv::Mat image(size, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::GaussianBlur(image, image, {0, 0}, 3);
  return image;
}

// Triangles of the box [lo, hi] (map frame).
void AppendBox(std::vector<Eigen::Vector3f>& out, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  auto corner = [&](int i) { return Eigen::Vector3f(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z()); };
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& f : faces)
    for (int k : {0, 1, 2, 0, 2, 3}) out.push_back(corner(f[k]));
}

// A room's light for the lit frames: ambient plus a warm light from above one side, a
// thumbnail of the bench's background from the bench's camera (so the exposure follower does
// its full per-frame work), the room as the proxy, and the room plus a pillar beside the
// character (inside the drawn rectangle, hiding none of it: the depth pass costs in full) as
// occluders.
RoomLight BenchRoomLight(const cv::Mat& background, const calib::Pose& camera_pose, const calib::Camera& camera) {
  RoomLight light;
  light.sh = ConstantSh({0.25, 0.25, 0.27}) + CapSh(Eigen::Vector3d(-0.5, -0.4, 0.77).normalized(), 0.1, {40, 36, 30});
  light.dominant = ExtractDominantLight(light.sh);
  light.thumbnails.push_back({camera_pose, LinearThumbnail(background, 40), {camera.fx, camera.fy, camera.cx, camera.cy}, camera.Size()});
  AppendBox(light.scene_triangles, {-3, -3, 0}, {3, 3, 2.8});
  // The occluders, as arview place makes them: without the character's floor (z = 0).
  for (size_t i = 0; i < light.scene_triangles.size(); i += 3) {
    const bool floor = light.scene_triangles[i].z() == 0 && light.scene_triangles[i + 1].z() == 0 &&
                       light.scene_triangles[i + 2].z() == 0;
    if (!floor) light.occluder_triangles.insert(light.occluder_triangles.end(), &light.scene_triangles[i], &light.scene_triangles[i] + 3);
  }
  AppendBox(light.occluder_triangles, {0.9f, -1.3f, 0}, {1.2f, -1.0f, 2.4f});
  return light;
}

// What a lit frame leaves out, to break its cost down (BM_ArFrameLitWithout).
enum class LitPart { kNothing, kCastShadow, kOcclusion, kPrt, kExposure };

void RunArFrame(benchmark::State& state, const std::string& name, Antialiasing antialiasing, bool lit = false,
                LitPart without = LitPart::kNothing, cv::Size size = {640, 480}, int weighted_targets = 0) {
  Subject* subject = GetSubject(name);
  if (subject == nullptr) {
    state.SkipWithError(("no " + name + " in ../shared/data/characters").c_str());
    return;
  }
  ArOptions options;
  options.antialiasing = antialiasing;
  if (lit) options.lighting = without == LitPart::kPrt ? LightingMode::kShUnshadowed : LightingMode::kShShadowed;
  options.cast_shadow = without != LitPart::kCastShadow;
  options.occlusion = without != LitPart::kOcclusion;
  const calib::Camera camera = BenchCamera(size);
  ArRenderer renderer(Context(), camera, options);
  renderer.AddCharacter(subject->animated->character(), subject->spec.placement());
  const cv::Mat background = Background(size);
  if (lit) {
    RoomLight light = BenchRoomLight(background, subject->camera_pose, camera);
    if (without == LitPart::kExposure) light.thumbnails.clear();  // the follower then keeps gain 1
    renderer.SetRoomLight(light);
    state.counters["prt_precompute_s"] = renderer.prt_seconds();
  }
  const Eigen::Vector3d viewpoint = subject->spec.placement().ViewpointFromCamera(subject->camera_pose.Center());
  double time = 0;
  cv::Mat frame;
  // The first `weighted_targets` morph targets at weights between 0.3 and 0.9, the others 0.
  std::vector<float> weights(subject->character->skeleton.morph_target_count(), 0.f);
  for (int k = 0; k < std::min(weighted_targets, static_cast<int>(weights.size())); ++k) weights[k] = 0.3f + 0.6f * (k % 7) / 6;
  auto animate = [&] {
    anim::AnimatorFrame f = subject->animated->Update(viewpoint, time);
    if (!weights.empty()) f.morph_weights = weights;
    return f;
  };
  // Warm-up outside the timing: llvmpipe compiles each new pipeline state at its first draw.
  for (int i = 0; i < 3; ++i) {
    const anim::AnimatorFrame f = animate();
    const anim::AnimatorFrame* out = &f;
    frame = renderer.Render(background, subject->camera_pose, {&out, 1});
  }
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    const anim::AnimatorFrame f = animate();
    const anim::AnimatorFrame* out = &f;
    frame = renderer.Render(background, subject->camera_pose, {&out, 1});
    benchmark::DoNotOptimize(frame.data);
    time += 1.0 / 30;
  }
  CountProcessCpu(state, cpu_start);
  // How much of the frame the character covers, and its size.
  cv::Mat diff, grey;
  cv::absdiff(frame, background, diff);
  cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
  state.counters["coverage_%"] = 100.0 * cv::countNonZero(grey > 8) / grey.total();
  int triangles = 0;
  for (const auto& m : subject->character->meshes) triangles += static_cast<int>(m.indices.size() / 3);
  state.counters["triangles"] = triangles;
  state.counters["gl_threads"] = Context().threads();
  state.counters["pixel_buffer"] = renderer.reads_through_pixel_buffer();
}

void BM_ArFrame(benchmark::State& state, std::string name) { RunArFrame(state, name, Antialiasing::kMsaa); }
void BM_ArFrameMorph(benchmark::State& state) {
  RunArFrame(state, "tube25k_morph52", Antialiasing::kMsaa, false, LitPart::kNothing, {640, 480}, static_cast<int>(state.range(0)));
}
void BM_ArFrameFace(benchmark::State& state) {
  RunArFrame(state, "tube25k_face52", Antialiasing::kMsaa, false, LitPart::kNothing, {640, 480}, static_cast<int>(state.range(0)));
}
void BM_ArFrameNoAa(benchmark::State& state, std::string name) { RunArFrame(state, name, Antialiasing::kNone); }
// The room's light (issue 14): SH through self-shadowed PRT, the exposure follower, the cast
// shadow from the dominant light and a depth-only occluder proxy, on top of BM_ArFrame.
void BM_ArFrameLit(benchmark::State& state, std::string name) { RunArFrame(state, name, Antialiasing::kMsaa, true); }
void BM_ArFrameLitNoAa(benchmark::State& state, std::string name) { RunArFrame(state, name, Antialiasing::kNone, true); }

// BM_ArFrame under one of SceneFences' policies (the cost of the fence hold), put back after.
void BM_ArFrameFences(benchmark::State& state, std::string name, SceneFencePolicy policy) {
  SetSceneFencePolicyForTiming(policy);
  RunArFrame(state, name, Antialiasing::kMsaa);
  SetSceneFencePolicyForTiming(SceneFencePolicy::kHold);
}

// The same at 1920x1080 (the field of view kept: the character covers the same share).
void BM_ArFrameLit1080p(benchmark::State& state, std::string name) {
  RunArFrame(state, name, Antialiasing::kMsaa, true, LitPart::kNothing, k1080p);
}

// Clears a 4x MSAA target of `size` and reads `rect` back, each iteration.
void RunReadbacks(benchmark::State& state, cv::Size size, const cv::Rect& rect, bool pixel_buffer) {
  const GlApi& gl = Context().gl();
  RenderTarget target(gl, size.width, size.height, 4);
  PixelReadback readback(gl);
  std::uint64_t checksum = 0;
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    target.Bind();
    gl.ClearColor(0.2f, 0.4f, 0.6f, 1.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    if (pixel_buffer) {
      target.StartReadBgra(rect, readback);
      checksum += readback.Map().data[0];
      readback.Unmap();
    } else {
      checksum += target.ReadBgraBottomUp(rect).data[0];
    }
  }
  benchmark::DoNotOptimize(checksum);
  CountProcessCpu(state, cpu_start);
}

// Resolving a 4x multisampled 1920x1080 target and reading it back, directly (glReadPixels into
// memory) or through a pixel buffer (PixelReadback: a copy into a buffer, a fence, a map). On a
// GPU the direct read waits for the GPU; on llvmpipe both are CPU copies.
void BM_Readback1080p(benchmark::State& state, bool pixel_buffer) {
  RunReadbacks(state, k1080p, cv::Rect(cv::Point(0, 0), k1080p), pixel_buffer);
}

// The fence hold's fixed cost a read-back, without a frame's drawing around it: a 4x MSAA
// 640x480 target cleared, a 64x64 corner resolved and read back, under one of SceneFences'
// policies (BM_ArFrameFences gives the same in a whole frame).
void BM_SmallReadbackFences(benchmark::State& state, SceneFencePolicy policy) {
  SetSceneFencePolicyForTiming(policy);
  RunReadbacks(state, {640, 480}, cv::Rect(0, 0, 64, 64), false);
  SetSceneFencePolicyForTiming(SceneFencePolicy::kHold);
}

// The lit frame without one of its parts: where its added cost goes.
void BM_ArFrameLitWithout(benchmark::State& state, std::string name, LitPart part) {
  RunArFrame(state, name, Antialiasing::kMsaa, true, part);
}

void BM_UndistortBackground(benchmark::State& state) {
  calib::Camera camera = BenchCamera();
  camera.dist = {-0.28, 0.07, 0.001, -0.0005, 0};
  cv::Mat map1, map2, out;
  cv::initUndistortRectifyMap(camera.K(), camera.DistCoeffs(), cv::noArray(), camera.K(), camera.Size(), CV_16SC2, map1, map2);
  const cv::Mat background = Background();
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    cv::remap(background, out, map1, map2, cv::INTER_LINEAR);
    benchmark::DoNotOptimize(out.data);
  }
  CountProcessCpu(state, cpu_start);
}

void BM_SynthRoomFrame(benchmark::State& state) {
  if (!std::filesystem::exists(std::filesystem::path(kOpenCvDocData) / "building.jpg")) {
    state.SkipWithError("needs Debian package opencv-doc");
    return;
  }
  static const RoomScene scene = MakeRoomScene();
  RoomRenderer renderer(Context(), scene, RoomCamera(), 4);
  const RoomPath path(10, 1);
  double t = 0;
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    cv::Mat frame = renderer.Render(path.At(t));
    benchmark::DoNotOptimize(frame.data);
    t = std::fmod(t + 0.37, 10.0);  // views from the whole path, not only its first second
  }
  CountProcessCpu(state, cpu_start);
}

BENCHMARK_CAPTURE(BM_ArFrame, Fox, std::string("Fox"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrame, CesiumMan, std::string("CesiumMan"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrame, tube25k, std::string("tube25k"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameNoAa, Fox, std::string("Fox"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameNoAa, CesiumMan, std::string("CesiumMan"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameNoAa, tube25k, std::string("tube25k"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLit, Fox, std::string("Fox"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLit, CesiumMan, std::string("CesiumMan"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLit, tube25k, std::string("tube25k"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitNoAa, Fox, std::string("Fox"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitNoAa, CesiumMan, std::string("CesiumMan"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitNoAa, tube25k, std::string("tube25k"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitWithout, tube25k_cast_shadow, std::string("tube25k"), LitPart::kCastShadow)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitWithout, tube25k_occlusion, std::string("tube25k"), LitPart::kOcclusion)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitWithout, tube25k_prt, std::string("tube25k"), LitPart::kPrt)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLitWithout, tube25k_exposure, std::string("tube25k"), LitPart::kExposure)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameFences, tube25k_hold, std::string("tube25k"), SceneFencePolicy::kHold)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameFences, tube25k_release_at_once, std::string("tube25k"), SceneFencePolicy::kReleaseAtOnce)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameFences, tube25k_none, std::string("tube25k"), SceneFencePolicy::kNone)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SmallReadbackFences, hold, SceneFencePolicy::kHold)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SmallReadbackFences, release_at_once, SceneFencePolicy::kReleaseAtOnce)
    ->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SmallReadbackFences, none, SceneFencePolicy::kNone)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ArFrameLit1080p, tube25k, std::string("tube25k"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Readback1080p, direct, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Readback1080p, pixel_buffer, true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_UndistortBackground)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SynthRoomFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ArFrameMorph)->Arg(0)->Arg(4)->Arg(16)->Arg(32)->ArgName("weighted")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ArFrameFace)->Arg(0)->Arg(8)->Arg(32)->ArgName("weighted")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace arview::render

int main(int argc, char** argv) {
  arview::KeepFreedHeapForReuse();  // as app/cli/main.cpp does, so that the figures are the app's
  // Our own flags first (Google Benchmark rejects unknown ones).
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strncmp(argv[i], "--gl_threads=", 13) == 0) {
      arview::render::g_gl.threads = std::atoi(argv[i] + 13);
    } else if (std::strncmp(argv[i], "--gl_device=", 12) == 0) {
      arview::render::g_gl.device = std::atoi(argv[i] + 12);
    } else if (std::strncmp(argv[i], "--gl=", 5) == 0) {
      try {
        arview::render::g_gl.backend = arview::render::ParseGlBackend(argv[i] + 5);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_render: --gl: %s\n", e.what());
        return 2;
      }
    } else {
      rest.push_back(argv[i]);
    }
  }
  int rest_count = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_count, rest.data());
  // The renderer goes into the report's context (console header and the JSON "context" object)
  // and to stderr: stdout carries only the report, so that --benchmark_format=json is pure JSON.
  std::string renderer;
  try {
    renderer = arview::render::Context().Description();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_render: %s\n", e.what());
    return 1;
  }
  benchmark::AddCustomContext("renderer", renderer);
  std::fprintf(stderr, "renderer: %s\n", renderer.c_str());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
