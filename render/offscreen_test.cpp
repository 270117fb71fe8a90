#include <gtest/gtest.h>

#include "render/gl_objects.h"
#include "render/offscreen.h"
#include "render/test_scene.h"

namespace arview::render {
namespace {

TEST(Offscreen, ParsesBackendNames) {
  EXPECT_EQ(ParseGlBackend("osmesa"), GlBackend::kOsMesa);
  EXPECT_EQ(ParseGlBackend("egl"), GlBackend::kEgl);
  EXPECT_EQ(ParseGlBackend("auto"), GlBackend::kAuto);
  EXPECT_EQ(ParseGlBackend("egl-device"), GlBackend::kEglDevice);
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
void ExpectClearReadsBack(GlBackend backend, bool egl_config_and_pbuffer = false) {
  std::unique_ptr<OffscreenContext> context;
  try {
    OffscreenOptions options = testing::GlOptions(backend, 2);
    options.egl_config_and_pbuffer = egl_config_and_pbuffer;
    context = OffscreenContext::Create(options);
  } catch (const RenderError& e) {
    GTEST_SKIP() << ToString(backend) << " unavailable here: " << e.what();
  }
  EXPECT_EQ(context->backend(), backend);
  std::printf("%s\n", context->Description().c_str());
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
// Mesa's EGL lists its software device on the device platform: the GPU path, run on llvmpipe.
TEST(Offscreen, EglDevicePlatformRendersIntoFramebufferObject) { ExpectClearReadsBack(GlBackend::kEglDevice); }
// A driver without configless and surfaceless contexts: a chosen config and a 1x1 pbuffer.
TEST(Offscreen, EglWithAConfigAndAPbufferRendersIntoFramebufferObject) {
  ExpectClearReadsBack(GlBackend::kEglDevice, true);
  ExpectClearReadsBack(GlBackend::kEgl, true);
}

TEST(Offscreen, RefusesToChangeThreadCountWithinProcess) {
  const GlBackend shared = testing::SharedContext().backend();  // fixes 2 threads for its library
  EXPECT_THROW(OffscreenContext::Create(testing::GlOptions(shared, 3)), RenderError);
}

// The renderer auto takes is described by what it is: a CPU renderer with its thread count.
TEST(Offscreen, DescribesTheRendererItTookAndWhatItTriedBefore) {
  const OffscreenContext& context = testing::SharedContext();
  const RendererInfo& info = context.info();
  EXPECT_NE(info.backend, GlBackend::kAuto);
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_FALSE(info.vendor.empty());
  ASSERT_FALSE(context.attempts().empty());
  EXPECT_TRUE(context.attempts().back().failure.empty());
  for (size_t i = 0; i + 1 < context.attempts().size(); ++i) EXPECT_FALSE(context.attempts()[i].failure.empty());
  if (info.software) {
    EXPECT_EQ(info.threads, 2);
    EXPECT_NE(context.Description().find(", 2 llvmpipe threads"), std::string::npos) << context.Description();
  }
}

// OffscreenOptions::Check: an EGL device with a backend that uses none would be ignored; the
// context is not even tried.
TEST(OffscreenOptionsCheck, ADeviceWithABackendThatUsesNoneIsRefusedNamingBoth) {
  OffscreenOptions options;
  options.backend = GlBackend::kOsMesa;
  options.device = 5;
  try {
    OffscreenContext::Create(options);
    FAIL() << "device 5 with osmesa accepted";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "gl.device 5 picks an EGL device: it needs gl.backend auto or egl-device (gl.backend osmesa "
                           "renders without one)");
  }
  try {
    options.Check(OptionNames({{"device", "--gl-device"}, {"backend", "--gl"}}));
    FAIL() << "device 5 with osmesa accepted";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "--gl-device 5 picks an EGL device: it needs --gl auto or egl-device (--gl osmesa renders "
                           "without one)");
  }
  options.backend = GlBackend::kEglDevice;
  EXPECT_NO_THROW(options.Check());
  options.threads = -1;
  try {
    options.Check();
    FAIL() << "threads -1 accepted";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "threads must be 0 (the calling thread) or more (got -1)");
  }
}

TEST(Offscreen, ANamedDeviceThatDoesNotExistIsRefused) {
  testing::SharedContext();
  try {
    OffscreenOptions options = testing::GlOptions(GlBackend::kAuto, 2);
    options.device = 64;
    OffscreenContext::Create(options);
    FAIL() << "device 64 accepted";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("GL device 64 (--gl-device 64) does not exist"), std::string::npos) << e.what();
  }
}

TEST(Offscreen, TheProbeListsEveryDeviceAndWhatAutoTakes) {
  const GlProbe probe = ProbeGl(testing::GlOptions(GlBackend::kAuto, 2));
  for (const GlProbe::Device& d : probe.devices) {
    EXPECT_TRUE(d.renderer || !d.failure.empty()) << "device " << d.device.index;
    if (d.renderer) {
      EXPECT_EQ(d.renderer->device, d.device.index);
    }
  }
  EXPECT_TRUE(probe.osmesa || !probe.osmesa_failure.empty());
  ASSERT_FALSE(probe.auto_attempts.empty()) << probe.auto_failure;
  EXPECT_EQ(probe.auto_attempts.back().candidate.kind == GlCandidateKind::kOsMesa,
            testing::SharedContext().backend() == GlBackend::kOsMesa);
}

TEST(Offscreen, RejectsImpossibleRenderTargets) {
  const GlApi& gl = testing::SharedContext().gl();
  EXPECT_THROW(RenderTarget(gl, 0, 10, 1), RenderError);
  EXPECT_THROW(RenderTarget(gl, 10, 10, 64), RenderError);
}

// Three coloured triangles across a 640 x 480 image, from gl_VertexID alone (no buffers).
GlName MakeTrianglesProgram(const GlApi& gl) {
  return MakeProgram(gl, "region test", R"(#version 450 core
out vec3 v_color;
void main() {
  const vec2 corners[9] = vec2[9](vec2(-0.9, -0.8), vec2(0.7, -0.6), vec2(-0.2, 0.9),
                                  vec2(0.2, -0.99), vec2(0.99, -0.9), vec2(0.33, 0.97),
                                  vec2(-0.97, 0.2), vec2(-0.1, 0.05), vec2(-0.6, 0.99));
  const vec3 colors[3] = vec3[3](vec3(1.0, 0.2, 0.1), vec3(0.1, 0.9, 0.3), vec3(0.2, 0.3, 1.0));
  v_color = colors[gl_VertexID % 3];
  gl_Position = vec4(corners[gl_VertexID], 0.1 * float(gl_VertexID / 3), 1.0);
}
)", R"(#version 450 core
in vec3 v_color;
out vec4 frag_color;
void main() { frag_color = vec4(v_color, 1.0); }
)");
}

void DrawTriangles(const GlApi& gl, GLuint program, GLuint vao) {
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  gl.Disable(GL_CULL_FACE);
  gl.UseProgram(program);
  gl.BindVertexArray(vao);
  gl.DrawArrays(GL_TRIANGLES, 0, 9);
  gl.BindVertexArray(0);
}

// The region's pixels are the full image's, whatever the rectangle, including after the target
// is made again for a larger rectangle and for one much smaller.
TEST(Offscreen, RegionTargetDrawsTheFullImagesPixelsInsideItsRectangle) {
  const GlApi& gl = testing::SharedContext().gl();
  const cv::Size image(640, 480);
  GlName program = MakeTrianglesProgram(gl);
  GlName vao = MakeVertexArray(gl);
  RenderTarget full(gl, image.width, image.height, 4);
  full.Bind();
  gl.ClearColor(0, 0, 0, 0);
  gl.ClearDepth(1.0);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  DrawTriangles(gl, program.get(), vao.get());
  RegionTarget region(gl, image, 4);
  for (const cv::Rect& rect : {cv::Rect(10, 20, 100, 80), cv::Rect(300, 100, 330, 370), cv::Rect(0, 0, 640, 480),
                               cv::Rect(33, 41, 50, 60), cv::Rect(600, 420, 40, 60), cv::Rect(250, 200, 130, 70)}) {
    region.Begin(rect);
    DrawTriangles(gl, program.get(), vao.get());
    const cv::Mat got = region.ReadBgra();
    const cv::Mat want = full.ReadBgra(rect);
    ASSERT_EQ(got.size(), rect.size());
    cv::Mat diff;
    cv::absdiff(got, want, diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    EXPECT_LE(worst, 1) << "rectangle " << rect;
    EXPECT_GT(cv::countNonZero(want.reshape(1)), 0) << "rectangle " << rect << " shows no triangle";
    // The compositing's read: the same pixels in OpenGL's bottom-up row order.
    cv::Mat bottom_up = region.ReadBgraBottomUp(), flipped;
    ASSERT_EQ(bottom_up.size(), rect.size());
    cv::flip(bottom_up, flipped, 0);
    EXPECT_EQ(cv::norm(flipped, got, cv::NORM_INF), 0) << "rectangle " << rect;
    EXPECT_LE(region.target_size().width, image.width) << "rectangle " << rect;
    EXPECT_LE(region.target_size().height, image.height) << "rectangle " << rect;
  }
}

// Making a target costs up to tens of milliseconds on llvmpipe: a rectangle that grows a little
// fits in the room kept, and a smaller one is drawn in the larger target until smaller ones
// have come for a second's worth of frames.
TEST(Offscreen, RegionTargetIsMadeAgainRarely) {
  const GlApi& gl = testing::SharedContext().gl();
  RegionTarget region(gl, cv::Size(640, 480), 4);
  region.Begin(cv::Rect(64, 64, 200, 150));
  const cv::Size first = region.target_size();
  EXPECT_GE(first.width, 250);  // a quarter more than the rectangle, in whole tiles
  EXPECT_LE(first.width, 256 + 64);
  region.Begin(cv::Rect(64, 64, 240, 180));  // grown by a fifth
  EXPECT_EQ(region.target_size(), first);
  for (int frame = 0; frame < 30; ++frame) {
    region.Begin(cv::Rect(64, 64, 60, 50));
    ASSERT_EQ(region.target_size(), first) << "after " << frame + 1 << " small rectangles";
  }
  region.Begin(cv::Rect(64, 64, 60, 50));
  EXPECT_LT(region.target_size().area(), first.area() / 2);
  region.ReserveWholeImage();
  EXPECT_EQ(region.target_size(), cv::Size(640, 480));
}

}  // namespace
}  // namespace arview::render
