// `arview record`'s capture guidance end to end (issue 56): three walks through the rendered
// room (synth/), each played by the emulated camera (tests/support/fake_v4l2_device.cpp) into
// `arview record`: the demo's walk (its first lap, which the demo maps) is not flagged, a camera
// turning on the spot is flagged for too little parallax, a camera carried along a blank stretch
// of wall for too few features; the window under Xvfb with a screenshot. 320x240 at 10 fps, 4 s
// each, so that the three walks render in seconds.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/camera.h"
#include "render/test_scene.h"
#include "synth/orbit_walk.h"
#include "synth/synth_room.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/run_command.h"
#include "tests/support/virtual_display.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::ShellQuote;

constexpr int kWidth = 320, kHeight = 240;
constexpr double kFps = 10, kSeconds = 4;
constexpr double kDemoWalkSeconds = 1340 / 30.0;  // the demo's two laps

// A recording folder of the room seen along `pose_at` (time in seconds), with sensor noise.
void WriteWalk(const fs::path& folder, const std::function<calib::Pose(double)>& pose_at) {
  fs::create_directories(folder / "frames");
  const calib::Camera camera = synth::RoomCamera(kWidth, kHeight);
  static const synth::RoomScene scene = synth::MakeRoomScene(synth::kOpenCvDocData, synth::SynthLighting::kWindow);
  synth::RoomRenderer renderer(render::testing::SharedContext(), scene, camera, 4);
  cv::RNG rng(7);
  std::ofstream list(folder / "frames.txt");
  list << "# timestamp path\n";
  for (int i = 0; i < kSeconds * kFps; ++i) {
    const double t = i / kFps;
    cv::Mat frame = renderer.Render(pose_at(t)), noise(frame.size(), CV_16SC3);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2);
    frame.convertTo(frame, CV_16SC3);
    cv::Mat noisy;
    cv::add(frame, noise, noisy);
    noisy.convertTo(noisy, CV_8UC3);
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.png", i);
    cv::imwrite((folder / name).string(), noisy);
    list << t << " " << name << "\n";
  }
  calib::SaveCamera(camera, folder / "camera.yaml");
}

// The demo's walk from 2 s into its first lap: walking round the character's spot, panning.
calib::Pose DemoWalk(double t) {
  static const synth::OrbitWalk walk(kDemoWalkSeconds, 1);
  return walk.At(2 + t);
}

// Standing in the room's middle and turning, 15 degrees a second, the camera held 10 cm in
// front of the body's axis (so it moves a little as it turns, as a person's does).
calib::Pose TurningOnTheSpot(double t) {
  const double yaw = (-20 + 15 * t) * M_PI / 180;
  const Eigen::Vector3d body(0.2, -0.3, 1.5), held = 0.1 * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0);
  return synth::HandHeldCameraPose(body + held, yaw, -0.1, 0);
}

// Carried sideways half a metre from the +x wall, low, below its photos: plain paint.
calib::Pose AlongABlankWall(double t) { return synth::HandHeldCameraPose({3.0, -1.5 + 0.4 * t, 0.35}, 0, 0, 0); }

fs::path Walks() {
  const fs::path root = fs::temp_directory_path() / ("arview_guidance_walks_v2_" + std::to_string(::getuid()));
  if (fs::exists(root / "done")) return root;
  WriteWalk(root / "demo", DemoWalk);
  WriteWalk(root / "turning", TurningOnTheSpot);
  WriteWalk(root / "blank", AlongABlankWall);
  std::ofstream(root / "done") << "1\n";
  return root;
}

fs::path TestDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("arview_guidance_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

testing::CommandResult Record(const fs::path& walk, const fs::path& dir) {
  return testing::RunWithEmulatedCamera({"record", "--device", testing::kEmulatedCamera, "--size", "320x240", "--fps",
                                         "10", "--seconds", "3.9", "--out", (dir / "rec").string()},
                                        {{"ARVIEW_FAKE_CAMERA_RECORDING", walk.string()}}, dir);
}

TEST(CaptureGuidanceRecord, TheDemosWalkIsLikelyToMap) {
  const fs::path dir = TestDir("demo");
  const auto r = Record(Walks() / "demo", dir);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  EXPECT_NE(r.out.find("capture guidance: likely to map: "), std::string::npos) << r.out << r.err;
  EXPECT_EQ(r.err.find("note: "), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(CaptureGuidanceRecord, TurningOnTheSpotIsFlaggedForTooLittleParallax) {
  const fs::path dir = TestDir("turning");
  const auto r = Record(Walks() / "turning", dir);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  EXPECT_NE(r.out.find("capture guidance: unlikely to map: too little parallax: "), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(": too little parallax: turning on the spot;"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(CaptureGuidanceRecord, ABlankWallIsFlaggedForTooFewFeatures) {
  const fs::path dir = TestDir("blank");
  const auto r = Record(Walks() / "blank", dir);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
  EXPECT_NE(r.out.find("capture guidance: unlikely to map: too few features in "), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(": too few features: a blank surface;"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// The window as a person sees it while turning on the spot: the picture with the points
// followed, the bars, the advice. ARVIEW_RECORD_SCREENSHOT names a file to keep it in (docs/).
class CaptureGuidanceWindow : public testing::XSessionTest<::testing::Test> {
 protected:
  void SetUp() override {
    Walks();
    REQUIRE_PROGRAM("xwd");
    REQUIRE_PROGRAM("convert");
    StartXSession("record_window");
  }
};

TEST_F(CaptureGuidanceWindow, ShowsThePictureTheBarsAndTheAdvice) {
  const char* bin_env = std::getenv("ARVIEW_BIN");
  const std::string line = "exec env DISPLAY=" + display_->name() + " LD_PRELOAD=" + ShellQuote(ARVIEW_FAKE_V4L2_LIBRARY) +
                           " ASAN_OPTIONS=\"$ASAN_OPTIONS:verify_asan_link_order=0\" ARVIEW_FAKE_CAMERA_RECORDING=" +
                           ShellQuote((Walks() / "turning").string()) + " " + ShellQuote(bin_env ? bin_env : "arview") +
                           " record --device " + testing::kEmulatedCamera + " --size 320x240 --fps 10 --window --out " +
                           ShellQuote((dir_ / "rec").string()) + " 2>" + ShellQuote((dir_ / "stderr.txt").string());
  const fs::path out = dir_ / "stdout.txt";
  testing::Child app({"sh", "-c", line}, out.string());
  // A screenshot once the guidance has said its note: the advice is on the panel.
  bool shot = false;
  for (int i = 0; i < 300 && app.Wait(0) < 0; ++i) {
    if (testing::ReadWholeFile((dir_ / "stderr.txt").string()).find("too little parallax") != std::string::npos) {
      testing::Shell("xwd -root -silent | convert xwd:- " + ShellQuote((dir_ / "window.png").string()), display_->name());
      shot = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(shot) << testing::ReadWholeFile((dir_ / "stderr.txt").string());
  // q in the window ends the recording; what was recorded stays. (xdotool's status is not
  // checked: the window may be gone before its own request after the key.)
  const std::string id = testing::Shell("xdotool search --name '^arview record '", display_->name());
  ASSERT_FALSE(id.empty());
  (void)std::system(("DISPLAY=" + display_->name() + " xdotool key --window " + id.substr(0, id.find('\n')) +
                     " q >/dev/null 2>&1").c_str());
  EXPECT_EQ(app.Wait(30), 0) << testing::ReadWholeFile((dir_ / "stderr.txt").string());
  const std::string said = testing::ReadWholeFile(out.string());
  EXPECT_NE(said.find("(stopped in the window)"), std::string::npos) << said;
  EXPECT_NE(said.find("capture guidance: unlikely to map: too little parallax"), std::string::npos) << said;
  EXPECT_TRUE(fs::exists(dir_ / "rec" / "frames.txt"));
  const cv::Mat screen = cv::imread((dir_ / "window.png").string());
  ASSERT_FALSE(screen.empty());
  const cv::Mat window = screen(cv::Rect(0, 0, kWidth + 260, 360));
  cv::Scalar mean, spread;
  cv::meanStdDev(window(cv::Rect(0, 0, kWidth, kHeight)), mean, spread);
  EXPECT_GT(spread[0], 20) << "the picture is not shown";
  // The advice in yellow on the panel.
  cv::Mat advice;
  cv::inRange(window(cv::Rect(kWidth, 250, 260, 110)), cv::Scalar(100, 200, 230), cv::Scalar(140, 255, 255), advice);
  EXPECT_GT(cv::countNonZero(advice), 100) << "no advice on the panel";
  if (const char* keep = std::getenv("ARVIEW_RECORD_SCREENSHOT")) {
    fs::copy_file(dir_ / "window.png", keep, fs::copy_options::overwrite_existing);
  }
}

}  // namespace
}  // namespace arview
