// Choosing the renderer from the command line: `arview info gl`, `--gl egl-device` (the GPU's way,
// on Mesa's software device here), --gl-device / ARVIEW_GL_DEVICE and --verbose, end to end.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/support/run_command.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::LineCount;
using testing::RunArview;

// ARVIEW_GL_DEVICE set for one test, unset after it (also when it fails).
class ScopedGlDeviceVariable {
 public:
  explicit ScopedGlDeviceVariable(const char* value) { setenv("ARVIEW_GL_DEVICE", value, 1); }
  ~ScopedGlDeviceVariable() { unsetenv("ARVIEW_GL_DEVICE"); }
};

// The project's figure standing at the map's origin (z up), and a 320x240 camera 3 m in front.
class GlCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arview_gl_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "scene.yaml") << "characters:\n  - name: figure\n    asset: builtin:figure\n    anchor:\n"
                                          "      position: [0, 0, 0]\n      rotation_deg: [90, 0, 0]\n    keys:\n"
                                          "      - viewpoint: [0, 0, 1]\n        clip: Idle\n";
    std::ofstream(dir_ / "camera.yaml")
        << "%YAML:1.0\n---\nimage_width: 320\nimage_height: 240\ncamera_matrix: !!opencv-matrix\n   rows: 3\n"
           "   cols: 3\n   dt: d\n   data: [ 260., 0., 159.5, 0., 260., 119.5, 0., 0., 1. ]\n"
           "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  testing::CommandResult Render(const std::string& gl, const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"render", "--scene", (dir_ / "scene.yaml").string(), "--camera",
                                     (dir_ / "camera.yaml").string(), "--pose", "0 -3 0.9 -0.7071068 0 0 0.7071068",
                                     "--out", (dir_ / out).string(), "--gl", gl};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunArview(args);
  }

  fs::path dir_;
};

TEST_F(GlCliTest, InfoGlListsTheDevicesAndWhatAutoTakes) {
  const auto text = RunArview({"info", "gl"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("EGL devices"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("OSMesa (--gl osmesa): "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("--gl auto takes: "), std::string::npos) << text.out;

  const auto json = RunArview({"info", "gl", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json j = nlohmann::json::parse(json.out);
  ASSERT_TRUE(j["auto"].is_string()) << json.out;
  for (const nlohmann::json& d : j["egl_devices"]) {
    EXPECT_TRUE(d["kind"] == "software" || d["kind"] == "hardware") << d.dump();
    // Each device is named in the text too, with its kind.
    EXPECT_NE(text.out.find("  " + std::to_string(d["index"].get<int>()) + "  " + d["kind"].get<std::string>()),
              std::string::npos)
        << text.out;
  }
  std::printf("%s", text.out.c_str());
}

// The device platform draws what OSMesa draws (both llvmpipe here).
TEST_F(GlCliTest, EglDeviceRendersTheSameFrameAsOsMesa) {
  const auto device = Render("egl-device", "device.png");
  const auto osmesa = Render("osmesa", "osmesa.png");
  if (osmesa.exit_code != 0 || device.exit_code != 0) {
    GTEST_SKIP() << "OSMesa or the EGL device platform missing here: " << osmesa.err << device.err;
  }
  EXPECT_NE(device.out.find("[egl-device "), std::string::npos) << device.out;
  const cv::Mat a = cv::imread((dir_ / "device.png").string()), b = cv::imread((dir_ / "osmesa.png").string());
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), b.size());
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  double worst = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
  EXPECT_LE(worst, 1);
  // The figure is in the picture (not a grey frame on both).
  cv::Mat from_grey;
  cv::absdiff(a, cv::Scalar(128, 128, 128), from_grey);
  EXPECT_GT(cv::countNonZero(from_grey.reshape(1) > 30), 2000);
}

TEST_F(GlCliTest, ADeviceThatDoesNotExistIsOneLineNamingIt) {
  const auto flag = Render("auto", "a.png", {"--gl-device", "63"});
  EXPECT_EQ(flag.exit_code, 1);
  EXPECT_EQ(LineCount(flag.err), 1) << flag.err;
  EXPECT_NE(flag.err.find("GL device 63 (--gl-device 63) does not exist"), std::string::npos) << flag.err;
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));
  {
    // Issue 57: a device the variable asks for was not said to come from it.
    const ScopedGlDeviceVariable absent("63");
    const auto from_variable = Render("auto", "a.png");
    EXPECT_EQ(from_variable.exit_code, 1);
    EXPECT_EQ(LineCount(from_variable.err), 1) << from_variable.err;
    EXPECT_NE(from_variable.err.find("GL device 63 (ARVIEW_GL_DEVICE=63) does not exist"), std::string::npos)
        << from_variable.err;
    EXPECT_FALSE(fs::exists(dir_ / "a.png"));
  }
  // Issue 57: --gl-device with a backend that takes no device was accepted and ignored.
  const auto ignored = Render("osmesa", "a.png", {"--gl-device", "5"});
  EXPECT_EQ(ignored.exit_code, 2);
  EXPECT_EQ(LineCount(ignored.err), 1) << ignored.err;
  EXPECT_NE(ignored.err.find("--gl-device 5 picks an EGL device: it needs --gl auto or egl-device (--gl osmesa "
                             "renders without one)"),
            std::string::npos)
      << ignored.err;
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));

  const ScopedGlDeviceVariable bad("first");
  const auto variable = Render("auto", "b.png");
  EXPECT_EQ(variable.exit_code, 1);
  EXPECT_EQ(LineCount(variable.err), 1) << variable.err;
  EXPECT_NE(variable.err.find("ARVIEW_GL_DEVICE='first'"), std::string::npos) << variable.err;
  // A backend that takes no device does not read the variable.
  EXPECT_EQ(Render("osmesa", "c.png").exit_code, 0);
  const auto info = RunArview({"info", "gl"});
  EXPECT_EQ(info.exit_code, 1) << info.out;
  EXPECT_NE(info.out.find("--gl auto finds nothing: ARVIEW_GL_DEVICE='first'"), std::string::npos) << info.out;
}

// A device asked for comes first; the variable names it as the flag does, and the flag wins.
TEST_F(GlCliTest, TheDeviceAskedForIsTaken) {
  const auto json = RunArview({"info", "gl", "--json"});
  ASSERT_EQ(json.exit_code, 0);
  const nlohmann::json devices = nlohmann::json::parse(json.out)["egl_devices"];
  if (devices.empty() || !devices[0]["usable"].get<bool>()) GTEST_SKIP() << "no usable EGL device here";
  const auto flag = Render("auto", "flag.png", {"--gl-device", "0", "--verbose"});
  ASSERT_EQ(flag.exit_code, 0) << flag.err;
  EXPECT_NE(flag.out.find("[egl-device 0: "), std::string::npos) << flag.out;
  const ScopedGlDeviceVariable zero("0");
  const auto variable = Render("auto", "variable.png");
  ASSERT_EQ(variable.exit_code, 0) << variable.err;
  EXPECT_NE(variable.out.find("[egl-device 0: "), std::string::npos) << variable.out;
}

}  // namespace
}  // namespace arview
