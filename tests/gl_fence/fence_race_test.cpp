// Issue 57's live crash (docs/reliability.md, "The live crash"): Mesa 22.3's llvmpipe may free
// a scene's fence while the rasterizer thread that signalled it has not yet unlocked the fence's
// mutex; that unlock then writes a zero into freed heap memory. The stall interposer
// (signal_stall.h) widens the window from nanoseconds (a rasterizer thread descheduled on a loaded
// machine) to milliseconds and counts every fence mutex destroyed while held. render/'s targets
// hold the fences (SceneFences) until a later one has signalled; without that, both tests fail
// (32 fence mutexes destroyed while held in the region test's 24 frames).

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <functional>
#include <memory>

#include "render/gl_objects.h"
#include "render/offscreen.h"
#include "tests/gl_fence/signal_stall.h"

namespace arview::render {
namespace {

constexpr int kFrames = 24;

// One context for the process: llvmpipe's thread count is fixed by the first.
OffscreenContext& RasterizerContext() {
  static const std::unique_ptr<OffscreenContext> context = [] {
    OffscreenOptions options;
    options.threads = 1;  // one rasterizer thread, as `arview run`: each fence has rank 1
    return OffscreenContext::Create(options);
  }();
  context->MakeCurrent();
  return *context;
}

struct StallCounts {
  long signaller_stalls = 0;
  long destroyed_while_held = 0;
};

// Runs `frame` kFrames times with the stall armed; what the interposer counted meanwhile.
StallCounts UnderStall(const std::function<void(int)>& frame) {
  const long stalls = testing::SignallerStalls(), destroyed = testing::MutexesDestroyedWhileHeld();
  testing::ArmSignalStall(true);
  for (int i = 0; i < kFrames; ++i) frame(i);
  testing::ArmSignalStall(false);
  return {testing::SignallerStalls() - stalls, testing::MutexesDestroyedWhileHeld() - destroyed};
}

// The render stage's read-back of the character's rectangle: a 4x multisampled region target,
// cleared, resolved (glBlitFramebuffer: the clear's scene is handed to the rasterizer and the
// resolve's begun at once) and read.
TEST(LlvmpipeFence, AResolvedRegionReadBackNeverFreesAFenceItsRasterizerStillHolds) {
  OffscreenContext& context = RasterizerContext();
  if (!context.info().software) GTEST_SKIP() << "not llvmpipe: " << context.Description();
  RegionTarget target(context.gl(), cv::Size(640, 480), 4);
  const StallCounts counts = UnderStall([&target](int i) {
    target.Begin(cv::Rect(100 + 7 * i, 120, 96, 128));
    const cv::Mat layer = target.ReadBgraBottomUp();
    ASSERT_EQ(layer.size(), cv::Size(96, 128));
    ASSERT_EQ(cv::countNonZero(layer.reshape(1)), 0);  // cleared to transparent black
  });
  // The stall must have met llvmpipe's fences, or this no longer exercises the race.
  EXPECT_GT(counts.signaller_stalls, 0);
  EXPECT_EQ(counts.destroyed_while_held, 0)
      << "llvmpipe destroyed a fence's mutex while its rasterizer thread held it (a write into freed memory)";
}

// A target without multisampling: each frame's clear is read straight back; the next frame's
// scene may reuse the last one's while its rasterizer still holds that scene's fence.
TEST(LlvmpipeFence, ReadBacksOfAPlainTargetNeverFreeAFenceItsRasterizerStillHolds) {
  OffscreenContext& context = RasterizerContext();
  if (!context.info().software) GTEST_SKIP() << "not llvmpipe: " << context.Description();
  const GlApi& gl = context.gl();
  RenderTarget target(gl, 160, 120, 0);
  const StallCounts counts = UnderStall([&](int i) {
    target.Bind();
    gl.ClearColor(0, static_cast<float>(i) / kFrames, 0, 1);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const cv::Mat image = target.ReadBgra();
    ASSERT_EQ(image.size(), cv::Size(160, 120));
  });
  EXPECT_GT(counts.signaller_stalls, 0);
  EXPECT_EQ(counts.destroyed_while_held, 0)
      << "llvmpipe destroyed a fence's mutex while its rasterizer thread held it (a write into freed memory)";
}

}  // namespace
}  // namespace arview::render
