#include "render/gl_selection.h"

#include <gtest/gtest.h>

namespace arview::render {
namespace {

// Devices as drivers list them: Mesa's software device, Mesa's render-node device of an
// integrated GPU, NVIDIA's device.
EglDeviceInfo MesaSoftware(int index) { return {index, "EGL_MESA_device_software EGL_EXT_device_drm_render_node", "", -1}; }
EglDeviceInfo MesaRenderNode(int index) {
  return {index, "EGL_EXT_device_drm EGL_EXT_device_drm_render_node", "/dev/dri/renderD128", -1};
}
EglDeviceInfo Nvidia(int index, int cuda) { return {index, "EGL_NV_device_cuda EGL_EXT_device_drm", "/dev/dri/card1", cuda}; }

GlCandidate Device(int index, bool software = false) { return {GlCandidateKind::kEglDevice, index, software}; }
const GlCandidate kSurfaceless{GlCandidateKind::kEglSurfaceless};
const GlCandidate kOsMesa{GlCandidateKind::kOsMesa};

std::string Names(const std::vector<GlCandidate>& plan) {
  std::string out;
  for (const GlCandidate& c : plan) out += (out.empty() ? "" : ", ") + c.Name();
  return out;
}

TEST(GlSelection, TellsSoftwareDevicesByTheirExtensionAsAWholeWord) {
  EXPECT_TRUE(MesaSoftware(0).software());
  EXPECT_FALSE(MesaRenderNode(0).software());
  EXPECT_FALSE(Nvidia(0, 0).software());
  EXPECT_FALSE((EglDeviceInfo{0, "EGL_MESA_device_software_x", "", -1}.software()));
}

TEST(GlSelection, AutoTakesHardwareFirstThenSurfacelessThenSoftwareThenOsMesa) {
  // As glvnd lists them on a laptop with an NVIDIA GPU: NVIDIA's, then Mesa's devices.
  const std::vector<EglDeviceInfo> devices = {Nvidia(0, 0), MesaRenderNode(1), MesaSoftware(2)};
  EXPECT_EQ(Names(PlanGlCandidates(GlBackend::kAuto, devices, std::nullopt)),
            "egl-device 0, egl-device 1, egl (surfaceless), egl-device 2, osmesa");
  // The software device listed first (Mesa's order on some machines) still comes after hardware.
  const std::vector<EglDeviceInfo> software_first = {MesaSoftware(0), MesaRenderNode(1)};
  EXPECT_EQ(PlanGlCandidates(GlBackend::kAuto, software_first, std::nullopt),
            (std::vector<GlCandidate>{Device(1), kSurfaceless, Device(0, true), kOsMesa}));
}

TEST(GlSelection, WithoutAnyDeviceAutoIsTheCpuPath) {
  EXPECT_EQ(PlanGlCandidates(GlBackend::kAuto, {}, std::nullopt), (std::vector<GlCandidate>{kSurfaceless, kOsMesa}));
  // This machine's case: Mesa's software device only.
  EXPECT_EQ(Names(PlanGlCandidates(GlBackend::kAuto, {MesaSoftware(0)}, std::nullopt)),
            "egl (surfaceless), egl-device 0, osmesa");
}

TEST(GlSelection, ARequestedDeviceComesFirstEvenASoftwareOne) {
  const std::vector<EglDeviceInfo> two_gpus = {Nvidia(0, 0), Nvidia(1, 1), MesaSoftware(2)};
  EXPECT_EQ(Names(PlanGlCandidates(GlBackend::kAuto, two_gpus, 1)),
            "egl-device 1, egl-device 0, egl (surfaceless), egl-device 2, osmesa");
  EXPECT_EQ(Names(PlanGlCandidates(GlBackend::kAuto, two_gpus, 2)),
            "egl-device 2, egl-device 0, egl-device 1, egl (surfaceless), osmesa");
  try {
    PlanGlCandidates(GlBackend::kAuto, two_gpus, 3);
    FAIL() << "device 3 of 3 accepted";
  } catch (const RenderError& e) {
    EXPECT_STREQ(e.what(), "GL device 3 does not exist: EGL lists 3 (0-2); 'arview info gl' lists them");
  }
  EXPECT_THROW(PlanGlCandidates(GlBackend::kEglDevice, {}, 0), RenderError);
  // Issue 57: a device asked for by the environment was reported without naming the variable.
  try {
    PlanGlCandidates(GlBackend::kAuto, two_gpus, 5, "ARVIEW_GL_DEVICE=5");
    FAIL() << "device 5 of 3 accepted";
  } catch (const RenderError& e) {
    EXPECT_STREQ(e.what(), "GL device 5 (ARVIEW_GL_DEVICE=5) does not exist: EGL lists 3 (0-2); 'arview info gl' "
                           "lists them");
  }
}

TEST(GlSelection, EglDeviceTriesDevicesOnlyAndTheOtherBackendsThemselvesOnly) {
  const std::vector<EglDeviceInfo> devices = {MesaSoftware(0), Nvidia(1, 0)};
  EXPECT_EQ(PlanGlCandidates(GlBackend::kEglDevice, devices, std::nullopt),
            (std::vector<GlCandidate>{Device(1), Device(0, true)}));
  EXPECT_TRUE(PlanGlCandidates(GlBackend::kEglDevice, {}, std::nullopt).empty());
  EXPECT_EQ(PlanGlCandidates(GlBackend::kOsMesa, devices, std::nullopt), std::vector<GlCandidate>{kOsMesa});
  EXPECT_EQ(PlanGlCandidates(GlBackend::kEgl, devices, std::nullopt), std::vector<GlCandidate>{kSurfaceless});
}

TEST(GlSelection, TheFlagOverridesTheEnvironmentVariableWhichMustBeAnIndex) {
  EXPECT_EQ(RequestedGlDevice(std::nullopt, nullptr), std::nullopt);
  EXPECT_EQ(RequestedGlDevice(std::nullopt, ""), std::nullopt);
  EXPECT_EQ(RequestedGlDevice(std::nullopt, "2"), 2);
  EXPECT_EQ(RequestedGlDevice(1, "2"), 1);
  for (const char* bad : {"-1", "one", "1x", " 1", "99999999999999999999"}) {
    try {
      RequestedGlDevice(std::nullopt, bad);
      FAIL() << "ARVIEW_GL_DEVICE=" << bad << " accepted";
    } catch (const RenderError& e) {
      EXPECT_NE(std::string(e.what()).find("ARVIEW_GL_DEVICE='" + std::string(bad) + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(GlSelection, AFailingDeviceIsSkippedWithItsReason) {
  const std::vector<GlCandidate> plan =
      PlanGlCandidates(GlBackend::kAuto, {Nvidia(0, 0), MesaRenderNode(1), MesaSoftware(2)}, std::nullopt);
  std::vector<std::string> tried;
  const std::vector<GlAttempt> attempts = TryGlCandidates(plan, [&](const GlCandidate& c) {
    tried.push_back(c.Name());
    if (c.device == 0) throw RenderError("its display does not initialise (EGL_NOT_INITIALIZED 0x3001)");
  });
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_EQ(attempts[0].candidate, Device(0));
  EXPECT_EQ(attempts[0].failure, "its display does not initialise (EGL_NOT_INITIALIZED 0x3001)");
  EXPECT_EQ(attempts[1].candidate, Device(1));
  EXPECT_EQ(attempts[1].failure, "");
  EXPECT_EQ(tried, (std::vector<std::string>{"egl-device 0", "egl-device 1"}));
}

TEST(GlSelection, WhenEverythingFailsTheMessageGivesEachReason) {
  const std::vector<GlCandidate> plan = PlanGlCandidates(GlBackend::kAuto, {}, std::nullopt);
  try {
    TryGlCandidates(
        plan, [](const GlCandidate& c) { throw RenderError(c.kind == GlCandidateKind::kOsMesa ? "no libOSMesa" : "no Mesa"); },
        "no EGL device: EGL library not found");
    FAIL() << "no candidate worked, yet no error";
  } catch (const RenderError& e) {
    EXPECT_STREQ(e.what(),
                 "no OpenGL 4.5 offscreen context (no EGL device: EGL library not found; egl (surfaceless): no Mesa; "
                 "osmesa: no libOSMesa)");
  }
}

}  // namespace
}  // namespace arview::render
