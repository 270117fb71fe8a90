#include <gtest/gtest.h>

#include "render/offscreen.h"
#include "render/test_scene.h"

namespace arview::render {
namespace {

TEST(Offscreen, ParsesBackendNames) {
  EXPECT_EQ(ParseGlBackend("osmesa"), GlBackend::kOsMesa);
  EXPECT_EQ(ParseGlBackend("egl"), GlBackend::kEgl);
  EXPECT_EQ(ParseGlBackend("auto"), GlBackend::kAuto);
  EXPECT_THROW(ParseGlBackend("vulkan"), RenderError);
}

TEST(Offscreen, SharedContextIsCoreFourFiveWithMultisampling) {
  OffscreenContext& context = testing::SharedContext();
  const std::string description = context.Description();
  EXPECT_NE(description.find("4.5"), std::string::npos) << description;
  EXPECT_GE(context.MaxSamples(), 4);
  std::printf("%s\n", description.c_str());
}

// Each backend, when present, clears a framebuffer object and reads the colour back.
void ExpectClearReadsBack(GlBackend backend) {
  std::unique_ptr<OffscreenContext> context;
  try {
    context = OffscreenContext::Create({backend, 2});
  } catch (const RenderError& e) {
    GTEST_SKIP() << ToString(backend) << " unavailable here: " << e.what();
  }
  EXPECT_EQ(context->backend(), backend);
  const GlApi& gl = context->gl();
  RenderTarget target(gl, 32, 24, 4);
  target.Bind();
  gl.ClearColor(1.0f, 0.5f, 0.0f, 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT);
  const cv::Mat image = target.ReadBgr();
  ASSERT_EQ(image.size(), cv::Size(32, 24));
  const cv::Vec3b pixel = image.at<cv::Vec3b>(5, 7);
  EXPECT_EQ(pixel[0], 0);
  EXPECT_NEAR(pixel[1], 128, 1);
  EXPECT_EQ(pixel[2], 255);
}

TEST(Offscreen, OsMesaBackendRendersIntoFramebufferObject) { ExpectClearReadsBack(GlBackend::kOsMesa); }
TEST(Offscreen, EglSurfacelessBackendRendersIntoFramebufferObject) { ExpectClearReadsBack(GlBackend::kEgl); }

TEST(Offscreen, RefusesToChangeThreadCountWithinProcess) {
  testing::SharedContext();  // fixes 2 threads for OSMesa (auto picks OSMesa here)
  EXPECT_THROW(OffscreenContext::Create({GlBackend::kOsMesa, 3}), RenderError);
}

TEST(Offscreen, RejectsImpossibleRenderTargets) {
  const GlApi& gl = testing::SharedContext().gl();
  EXPECT_THROW(RenderTarget(gl, 0, 10, 1), RenderError);
  EXPECT_THROW(RenderTarget(gl, 10, 10, 64), RenderError);
}

}  // namespace
}  // namespace arview::render
