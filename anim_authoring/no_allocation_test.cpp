// The runtime allocates nothing per frame (issue 13): Animator::Update on the four-action
// schedule of the speed goal (tests/support/four_action_schedule.h), counted at malloc.
//
// This binary replaces malloc, calloc and realloc with counting forwarders to glibc's own
// (__libc_malloc, ...), so every allocation is seen: operator new, Eigen's dynamic matrices,
// std::vector. Sanitizer builds bring their own allocator, which cannot be replaced; there the
// count comes from the sanitizer's malloc hook, which its allocator calls for every malloc,
// calloc, realloc and operator new.

#include "anim/animator.h"
#include "anim/balance_shift.h"
#include "anim/placed_character.h"
#include "anim/view_adaptive.h"
#include "tests/support/face_schedule.h"
#include "anim/gaze.h"
#include "tests/support/eyed_head.h"
#include "tests/support/four_action_schedule.h"
#include "tests/support/standing_recording.h"
#include "tests/support/test_data.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstddef>
#include <memory>

#include "base/sanitizer_build.h"  // ARVIEW_SANITIZED_ALLOCATOR: whether malloc is counted through the sanitizer's hooks

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

#if !defined(ARVIEW_SANITIZED_ALLOCATOR) && defined(__GLIBC__)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
}
#define ARVIEW_COUNTS_ALLOCATIONS 1
#elif defined(ARVIEW_SANITIZED_ALLOCATOR)
// The sanitizer runtimes' (ASan, TSan) public hook; GCC 12 ships no header declaring it.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, std::size_t),
                                                         void (*free_hook)(const volatile void*));
namespace {
void CountAllocation(const volatile void*, std::size_t) { g_allocations.fetch_add(1, std::memory_order_relaxed); }
void IgnoreFree(const volatile void*) {}
[[maybe_unused]] const int g_hook_installed = __sanitizer_install_malloc_and_free_hooks(CountAllocation, IgnoreFree);
}  // namespace
#define ARVIEW_COUNTS_ALLOCATIONS 1
#endif

namespace arview::authoring {
namespace {

#ifdef ARVIEW_COUNTS_ALLOCATIONS
// The counter sees allocations: a vector's growth is one.
TEST(NoAllocation, TheCounterCountsAVector) {
  const long before = g_allocations.load();
  std::vector<double>* v = new std::vector<double>(1000, 1.0);
  const long after = g_allocations.load();
  delete v;
  EXPECT_GE(after - before, 2);
}
#endif

void ExpectUpdatesAllocateNothing([[maybe_unused]] testing::FourActionSchedule::Gesture gesture, [[maybe_unused]] bool dib) {
#ifndef ARVIEW_COUNTS_ALLOCATIONS
  GTEST_SKIP() << "allocations are counted only with glibc's malloc or a sanitizer's";
#else
  testing::FourActionSchedule schedule(gesture, dib);
  schedule.Step(1.0 / 60);  // the first frame may size scratch buffers
  const long before = g_allocations.load();
  // 20 s at 60 frames/s: the viewer goes round 5.5 times, the gesture is re-timed 5 times, the
  // idle chains step past many extrema.
  bool all_finite = true;
  for (int frame = 0; frame < 1200; ++frame) {
    const anim::AnimatorFrame& f = schedule.Step(1.0 / 60);
    all_finite = all_finite && f.skinning_matrices[0].allFinite();
  }
  const long allocations = g_allocations.load() - before;
  EXPECT_TRUE(all_finite);
  EXPECT_EQ(allocations, 0) << "allocations in 1200 Animator::Update calls";
#endif
}

TEST(NoAllocation, FourActionScheduleWithPointGesture) {
  ARVIEW_REQUIRE_DATA_PATH(std::filesystem::path(testing::kBcnEpileptic), "Debian package assimp-testmodels");
  ExpectUpdatesAllocateNothing(testing::FourActionSchedule::Gesture::kPoint, false);
  ExpectUpdatesAllocateNothing(testing::FourActionSchedule::Gesture::kPoint, true);
}

TEST(NoAllocation, FourActionScheduleWithMirroredGesture) {
  ARVIEW_REQUIRE_DATA_PATH(std::filesystem::path(testing::kBcnEpileptic), "Debian package assimp-testmodels");
  ExpectUpdatesAllocateNothing(testing::FourActionSchedule::Gesture::kMirroredClip, false);
}

// The face channel: 52 morph targets keyed by three clips (one mirrored, one on a layer above),
// their weights sampled and blended every frame, and a face layer's write after each update.
TEST(NoAllocation, MorphTargetWeightsSampledBlendedAndSet) {
#ifndef ARVIEW_COUNTS_ALLOCATIONS
  GTEST_SKIP() << "allocations are counted only with glibc's malloc or a sanitizer's";
#else
  testing::FaceSchedule face(52);
  face.Step(1.0 / 60);
  const long before = g_allocations.load();
  float sum = 0;
  for (int frame = 0; frame < 1200; ++frame) {
    const anim::AnimatorFrame& f = face.Step(1.0 / 60);
    for (float w : f.morph_weights) sum += w;
  }
  const long allocations = g_allocations.load() - before;
  EXPECT_GT(sum, 0) << "the clips key the weights";
  EXPECT_EQ(allocations, 0) << "allocations in 1200 Animator::Update calls with morph targets";
#endif
}

// The balance-shift layer with the idle synthesizer's variations on top, learned from the
// constructed standing recording: 10 minutes at 60 Hz, over a hundred transitions chosen and fitted.
TEST(NoAllocation, BalanceLayerOverTheIdleSynthesizer) {
#ifndef ARVIEW_COUNTS_ALLOCATIONS
  GTEST_SKIP() << "allocations are counted only with glibc's malloc or a sanitizer's";
#else
  const auto standing = testing::LearnFromStanding(testing::LongStanding());
  ASSERT_TRUE(standing->balance);
  const auto sk = standing->skeleton();
  auto idle = std::make_shared<anim::IdleSynthesizer>(sk, std::make_shared<const anim::IdleModel>(standing->idle), 1);
  anim::BalanceShifter layer(sk, std::make_shared<const anim::BalanceModel>(*standing->balance), 1, idle);
  anim::LocalPose pose(sk->size());
  ASSERT_TRUE(layer.Sample(0, {}, pose));
  const long before = g_allocations.load();
  bool sampled = true;
  int transitions = 0, segment = -1;
  for (int frame = 1; frame <= 36000; ++frame) {
    sampled = layer.Sample(frame / 60.0, {}, pose) && sampled;
    transitions += layer.state().segment >= 0 && layer.state().segment != segment;
    segment = layer.state().segment;
  }
  const long allocations = g_allocations.load() - before;
  EXPECT_TRUE(sampled);
  EXPECT_GT(transitions, 100);
  EXPECT_EQ(allocations, 0) << "allocations in 36000 samples";
#endif
}

// Gaze (anim/gaze.h) on a head with two eyes and their lids: 10 minutes at 60 Hz of saccades,
// fixations and blinks, the viewer moving in front, one backward jump (a replay's restart).
TEST(NoAllocation, GazeOverTenMinutes) {
#ifndef ARVIEW_COUNTS_ALLOCATIONS
  GTEST_SKIP() << "allocations are counted only with glibc's malloc or a sanitizer's";
#else
  const anim::Skeleton sk = testing::EyedHead();
  anim::GazeOptions options;
  options.mode = anim::GazeMode::kTalking;
  anim::Gaze gaze(sk, anim::FindGazeRig(sk), options);
  anim::LocalPose pose = anim::LocalPose::Rest(sk);
  std::vector<Eigen::Matrix4d> model(sk.size());
  anim::MustRun(anim::LocalToModelJob{&sk, &pose, model}, "test");
  gaze.Apply(0, Eigen::Vector3d(0, 1.6, 1), model, pose);
  const long before = g_allocations.load();
  int blinks = 0;
  for (int frame = 1; frame <= 36000; ++frame) {
    const double t = frame / 60.0;
    gaze.Apply(frame == 18000 ? 1.0 : t, Eigen::Vector3d(std::sin(t), 1.6, 1.2), model, pose);
    blinks += gaze.frame().blinks_begun;
  }
  const long allocations = g_allocations.load() - before;
  EXPECT_GT(blinks, 200);
  EXPECT_EQ(allocations, 0) << "allocations in 36000 Gaze::Apply calls";
#endif
}

// The face through the whole runtime: an eyed head with three targets, view-adaptive keys that
// key the targets differently (blended as the joints are), the same blend mirrored on a layer
// above (left and right targets exchanged), gaze posing the eyes from the chain to the head
// (Animator::Update); and PlacedCharacter::Update with gaze. 20 s at 60 Hz each.
TEST(NoAllocation, GazeAndTheViewAdaptiveFaceThroughTheAnimator) {
#ifndef ARVIEW_COUNTS_ALLOCATIONS
  GTEST_SKIP() << "allocations are counted only with glibc's malloc or a sanitizer's";
#else
  auto character = std::make_shared<anim::Character>();
  character->source = "eyed-head";
  character->skeleton = testing::EyedHead();
  character->skeleton.morph_targets = {"eyeBlinkLeft", "eyeBlinkRight", "jawOpen"};
  const auto sk = std::shared_ptr<const anim::Skeleton>(character, &character->skeleton);
  std::vector<anim::ViewAdaptiveKey> keys;
  for (int k = 0; k < 4; ++k) {
    auto clip = std::make_shared<anim::Clip>();
    clip->name = "key" + std::to_string(k);
    clip->duration = 2;
    clip->tracks.resize(sk->size());
    const double turn = (k - 1.5) * 0.3;
    clip->tracks[0].rotation = {{0.0, Eigen::Quaterniond(Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitY()))},
                                {2.0, Eigen::Quaterniond(Eigen::AngleAxisd(-turn, Eigen::Vector3d::UnitY()))}};
    clip->weight_tracks = {{k % 3, {{0.0, 0.0}, {1.0, 0.25 * (k + 1)}, {2.0, 0.0}}}};
    const double a = k * M_PI / 2;
    keys.push_back({Eigen::Vector3d(std::sin(a), 0, std::cos(a)), clip});
  }
  auto blend = std::make_shared<anim::ViewAdaptiveBlend>(sk, keys);
  auto schedule = std::make_shared<anim::Schedule>(sk);
  schedule->Add({blend, {}, 0, true, "view"});
  schedule->Add({std::make_shared<anim::Mirror>(blend, sk), {}, 0, true, "mirrored", 1});
  schedule->SetLiveWeight(1, 0.4);
  anim::AnimatorOptions options;
  options.gaze = anim::GazeSetup{anim::FindGazeRig(*sk), anim::GazeOptions{}};
  anim::Animator animator(sk, schedule, options, blend);
  anim::PlacedCharacterParts parts;
  parts.character = character;
  parts.blend = std::make_shared<anim::ViewAdaptiveBlend>(sk, keys);
  parts.gaze = options.gaze;
  anim::PlacedCharacter placed(std::move(parts));
  auto inputs = [](int frame) {
    const double t = frame / 60.0;
    anim::FrameInputs in;
    in.viewpoint = Eigen::Vector3d(std::sin(t), 0.1, std::cos(t)).normalized();
    in.viewer = Eigen::Vector3d(0.5 * std::sin(t), 1.7, 1.2);
    return in;
  };
  animator.Update(0, inputs(0));
  placed.Update(inputs(0).viewpoint, 0, inputs(0).viewer);
  const long before = g_allocations.load();
  float face = 0;
  int on_viewer = 0;
  for (int frame = 1; frame <= 1200; ++frame) {
    const anim::AnimatorFrame& f = animator.Update(frame / 60.0, inputs(frame));
    face += f.morph_weights[0] + f.morph_weights[1];
    on_viewer += f.gaze.eyes_on_viewer;
    on_viewer += placed.Update(inputs(frame).viewpoint, frame / 60.0, inputs(frame).viewer).gaze.eyes_on_viewer;
  }
  const long allocations = g_allocations.load() - before;
  EXPECT_GT(face, 0) << "the keys key the face";
  EXPECT_GT(on_viewer, 0) << "the eyes met the viewer";
  EXPECT_EQ(allocations, 0) << "allocations in 1200 Animator::Update and 1200 PlacedCharacter::Update calls with gaze";
#endif
}

}  // namespace
}  // namespace arview::authoring
