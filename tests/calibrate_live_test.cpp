// `arview calibrate --device` and `--recording` end to end (issue 56): the emulated camera
// (tests/support/fake_v4l2_device.cpp) plays a chessboard waved in front of a camera whose
// intrinsics and distortion are known exactly (tests/support/rendered_board.h: held still at
// places across the image, near and far, tilted, carried between them with motion blur, sensor
// noise), and the calibration the command writes must match them; the same for a ChArUco board
// seen in part; the window under Xvfb, and the inputs that hold no board.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "calib/camera.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/rendered_board.h"
#include "tests/support/run_command.h"
#include "tests/support/virtual_display.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::ShellQuote;

// A walk rendered once per machine into `name` (a minute or two on a loaded machine).
fs::path SharedWalk(const std::string& name, const testing::BoardWalk& board_walk) {
  const fs::path walk = fs::temp_directory_path() / (name + "_" + std::to_string(::getuid()));
  if (fs::exists(walk / "frames.txt")) return walk;
  const fs::path rendering = walk.string() + ".rendering_" + std::to_string(::getpid());
  fs::remove_all(rendering);
  testing::WriteBoardWalk(rendering, board_walk);
  std::error_code ec;
  fs::rename(rendering, walk, ec);  // fails harmlessly when a parallel test got there first
  fs::remove_all(rendering, ec);
  return walk;
}

// The chessboard's walk (about 35 s of footage).
fs::path SharedBoardWalk() { return SharedWalk("arview_board_walk_v2", {}); }

// The ChArUco board's (26 s at 10 fps, part of the board out of the image at the corners).
fs::path SharedCharucoWalk() { return SharedWalk("arview_charuco_walk_v3", testing::CharucoWalk()); }

fs::path TestDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("arview_calibrate_live_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The footage's length the command reports ("... over 23.4 s").
double FootageSeconds(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex(R"(frames \(\d+ with the board\) over ([0-9.]+) s)"))) return -1;
  return std::stod(m[1]);
}

// The issue's figure: fx, fy, cx, cy within 0.5 % of the truth, k1 within 0.02.
void ExpectTheTruth(const calib::Camera& found, const calib::Camera& truth) {
  EXPECT_NEAR(found.fx, truth.fx, 0.005 * truth.fx);
  EXPECT_NEAR(found.fy, truth.fy, 0.005 * truth.fy);
  EXPECT_NEAR(found.cx, truth.cx, 0.005 * truth.cx);
  EXPECT_NEAR(found.cy, truth.cy, 0.005 * truth.cy);
  EXPECT_NEAR(found.dist[0], truth.dist[0], 0.02);
  std::printf("[calibrated] fx %.2f (truth %.2f) fy %.2f (%.2f) cx %.2f (%.2f) cy %.2f (%.2f) k1 %.4f (%.4f) k2 %.4f (%.4f)\n",
              found.fx, truth.fx, found.fy, truth.fy, found.cx, truth.cx, found.cy, truth.cy, found.dist[0],
              truth.dist[0], found.dist[1], truth.dist[1]);
}

TEST(CalibrateLive, TheEmulatedCameraWavingABoardGivesTheLensWithinHalfAPercent) {
  const fs::path walk = SharedBoardWalk();
  const fs::path dir = TestDir("device");
  const auto r = testing::RunWithEmulatedCamera(
      {"calibrate", "--device", testing::kEmulatedCamera, "--fps", "15", "--board", "9x6", "--square", "0.025", "--out",
       (dir / "camera.yaml").string(), "--report", (dir / "report.png").string(), "--no-window"},
      {{"ARVIEW_FAKE_CAMERA_RECORDING", walk.string()}}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::printf("%s", r.out.c_str());
  // Views were taken automatically, one line each, until the coverage sufficed.
  EXPECT_NE(r.out.find("view 1 taken (frame "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("coverage suffices: "), std::string::npos) << r.out;
  const double seconds = FootageSeconds(r.out);
  EXPECT_GT(seconds, 0) << r.out;
  EXPECT_LT(seconds, 90) << r.out;
  EXPECT_NE(r.out.find("projection uncertainty at 1 m: "), std::string::npos) << r.out;
  const calib::Camera found = calib::LoadCamera(dir / "camera.yaml");
  ExpectTheTruth(found, calib::LoadCamera(walk / "truth.yaml"));
  // The emulated camera's focus (40) was locked and is written with the calibration.
  ASSERT_TRUE(found.focus.has_value());
  EXPECT_EQ(*found.focus, 40);
  const cv::Mat report = cv::imread((dir / "report.png").string());
  EXPECT_EQ(report.cols, 3 * found.width);
  fs::remove_all(dir);
}

TEST(CalibrateLive, ARecordingIsPickedTheSameWay) {
  const fs::path walk = SharedBoardWalk();
  const fs::path dir = TestDir("recording");
  const auto r = testing::RunArview({"calibrate", "--recording", walk.string(), "--out", (dir / "camera.yaml").string(),
                                     "--no-window"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("coverage suffices: "), std::string::npos) << r.out;
  EXPECT_LT(FootageSeconds(r.out), 90) << r.out;
  const calib::Camera found = calib::LoadCamera(dir / "camera.yaml");
  ExpectTheTruth(found, calib::LoadCamera(walk / "truth.yaml"));
  EXPECT_FALSE(found.focus.has_value());  // a recording says nothing of the focus
  fs::remove_all(dir);
}

TEST(CalibrateLive, ARecordingWithoutABoardIsOneClearLine) {
  const fs::path dir = TestDir("noboard");
  fs::create_directories(dir / "rec" / "frames");
  std::string list;
  for (int i = 0; i < 5; ++i) {
    const std::string name = "frames/" + std::to_string(i) + ".png";
    cv::imwrite((dir / "rec" / name).string(), cv::Mat(120, 160, CV_8UC3, cv::Scalar(90, 100, 110)));
    list += std::to_string(i * 0.1) + " " + name + "\n";
  }
  std::ofstream(dir / "rec" / "frames.txt") << list;
  const auto r = testing::RunArview({"calibrate", "--recording", (dir / "rec").string(), "--out",
                                     (dir / "camera.yaml").string(), "--no-window"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("arview: --recording " + (dir / "rec").string() + ": no 9x6 chessboard in any of its 5 frames"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "camera.yaml"));
  const auto missing = testing::RunArview({"calibrate", "--recording", (dir / "none").string(), "--out",
                                           (dir / "camera.yaml").string(), "--no-window"});
  EXPECT_NE(missing.err.find("no frames.txt there"), std::string::npos) << missing.err;
  fs::remove_all(dir);
}

TEST(CalibrateLive, ALiveCameraThatSeesNoBoardIsOneClearLine) {
  const fs::path dir = TestDir("grey");
  // The emulated camera without a recording: grey frames.
  const auto r = testing::RunWithEmulatedCamera({"calibrate", "--device", testing::kEmulatedCamera, "--out",
                                                 (dir / "camera.yaml").string(), "--no-window", "--seconds", "1"},
                                                {}, dir);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("--seconds reached: 0 view(s) taken"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(std::string("arview: ") + testing::kEmulatedCamera + ": no 9x6 chessboard in any of its"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "camera.yaml"));
  const auto charuco = testing::RunWithEmulatedCamera(
      {"calibrate", "--device", testing::kEmulatedCamera, "--charuco", "--board", "10x7", "--out",
       (dir / "camera.yaml").string(), "--no-window", "--seconds", "1"},
      {}, dir);
  EXPECT_EQ(charuco.exit_code, 1) << charuco.out << charuco.err;
  EXPECT_NE(charuco.err.find(std::string("arview: ") + testing::kEmulatedCamera +
                             ": no 10x7 ChArUco board in any of its"),
            std::string::npos)
      << charuco.err;
  EXPECT_NE(charuco.err.find("(--board counts squares, columns x rows; --dictionary DICT_5X5_100)"), std::string::npos)
      << charuco.err;
  fs::remove_all(dir);
}

// ChArUco live (issue 56): the board's corners are told apart by its markers, so a view of part of
// it counts: the walk holds it half out of the image at the image's corners, where a chessboard
// cannot be found at all, and the lens must come out as the chessboard's does.
TEST(CalibrateLive, AChArUcoBoardSeenInPartGivesTheLensWithinHalfAPercent) {
  const fs::path walk = SharedCharucoWalk();
  const fs::path dir = TestDir("charuco");
  const auto r = testing::RunWithEmulatedCamera(
      {"calibrate", "--device", testing::kEmulatedCamera, "--fps", "10", "--charuco", "--board", "10x7", "--square",
       "0.05", "--out", (dir / "camera.yaml").string(), "--no-window", "--seconds", "40"},
      {{"ARVIEW_FAKE_CAMERA_RECORDING", walk.string()}}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.out.find("coverage suffices: "), std::string::npos) << r.out;
  EXPECT_LT(FootageSeconds(r.out), 90) << r.out;
  // Views of part of the board were taken: fewer than its 54 corners.
  int partial = 0;
  const std::regex view(R"(frame \d+ at [0-9.]+ s\s+(\d+)\s)");
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), view); it != std::sregex_iterator(); ++it) {
    partial += std::stoi((*it)[1]) < 54;
  }
  EXPECT_GE(partial, 2) << r.out;
  ExpectTheTruth(calib::LoadCamera(dir / "camera.yaml"), calib::LoadCamera(walk / "truth.yaml"));
  fs::remove_all(dir);
}

// The window as a person sees it: the frame with the corners, the coverage bars filling, the
// views taken; a screenshot (xwd, ImageMagick) while it runs. ARVIEW_CALIBRATE_SCREENSHOT and
// ARVIEW_CALIBRATE_CHARUCO_SCREENSHOT name files to keep them in (docs/calibration.md's pictures).
class CalibrateWindow : public testing::XSessionTest<::testing::Test> {
 protected:
  void SetUp() override {
    REQUIRE_PROGRAM("xwd");
    REQUIRE_PROGRAM("convert");
    StartXSession("calibrate_window");
  }

  // Runs `arview calibrate --device` in the window on the emulated camera playing `walk` with
  // `board_args`, takes a screenshot once six views are taken, waits for the calibration and
  // returns the window (the frame, 640x480, and the panel on its right).
  cv::Mat CalibrateAndShoot(const fs::path& walk, const std::string& board_args, const char* keep_env) {
    const char* bin_env = std::getenv("ARVIEW_BIN");
    const std::string line = "exec env DISPLAY=" + display_->name() + " LD_PRELOAD=" +
                             ShellQuote(ARVIEW_FAKE_V4L2_LIBRARY) +
                             " ASAN_OPTIONS=\"$ASAN_OPTIONS:verify_asan_link_order=0\" ARVIEW_FAKE_CAMERA_RECORDING=" +
                             ShellQuote(walk.string()) + " " + ShellQuote(bin_env ? bin_env : "arview") +
                             " calibrate --device " + testing::kEmulatedCamera + " " + board_args + " --out " +
                             ShellQuote((dir_ / "camera.yaml").string()) + " 2>" +
                             ShellQuote((dir_ / "stderr.txt").string());
    const fs::path out = dir_ / "stdout.txt";
    testing::Child app({"sh", "-c", line}, out.string());
    // A screenshot once a few views are taken: the bars part-filled.
    bool shot = false;
    for (int i = 0; i < 1200 && app.Wait(0) < 0; ++i) {
      if (testing::ReadWholeFile(out.string()).find("view 6 taken") != std::string::npos) {
        testing::Shell("xwd -root -silent | convert xwd:- " + ShellQuote((dir_ / "window.png").string()),
                       display_->name());
        shot = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    EXPECT_TRUE(shot) << testing::ReadWholeFile(out.string()) << testing::ReadWholeFile((dir_ / "stderr.txt").string());
    EXPECT_EQ(app.Wait(120), 0) << testing::ReadWholeFile((dir_ / "stderr.txt").string());
    EXPECT_TRUE(fs::exists(dir_ / "camera.yaml"));
    const cv::Mat screen = cv::imread((dir_ / "window.png").string());
    if (screen.empty()) return {};
    if (const char* keep = std::getenv(keep_env)) {
      fs::copy_file(dir_ / "window.png", keep, fs::copy_options::overwrite_existing);
    }
    // The window at the top-left corner of the bare X screen.
    return screen(cv::Rect(0, 0, 640 + 260, 480)).clone();
  }
};

// The frame shown, and some bar filled (green or orange) on the panel.
void ExpectTheFrameAndFilledBars(const cv::Mat& window) {
  ASSERT_FALSE(window.empty());
  cv::Scalar mean, spread;
  cv::meanStdDev(window(cv::Rect(0, 0, 640, 480)), mean, spread);
  EXPECT_GT(spread[0], 20) << "the frame is not shown";
  cv::Mat hsv, saturated;
  cv::cvtColor(window(cv::Rect(640, 40, 260, 150)), hsv, cv::COLOR_BGR2HSV);
  cv::inRange(hsv, cv::Scalar(0, 120, 120), cv::Scalar(180, 255, 255), saturated);
  EXPECT_GT(cv::countNonZero(saturated), 500) << "no bar is filled";
}

TEST_F(CalibrateWindow, ShowsTheCornersTheBarsAndTheViewsAndCalibratesWhenTheyAreFull) {
  const cv::Mat window = CalibrateAndShoot(SharedBoardWalk(), "--fps 15", "ARVIEW_CALIBRATE_SCREENSHOT");
  ExpectTheFrameAndFilledBars(window);
}

// A ChArUco board, end to end in the window: the frame, the bars and the overlay's green (the
// outline of the part found and the corners' dots; the outline itself is checked in cli_tests,
// CalibrationWindow.*), and a calibration written.
TEST_F(CalibrateWindow, OutlinesThePartOfAChArUcoBoardFoundAndCalibrates) {
  const cv::Mat window = CalibrateAndShoot(SharedCharucoWalk(), "--fps 10 --charuco --board 10x7 --square 0.05",
                                           "ARVIEW_CALIBRATE_CHARUCO_SCREENSHOT");
  ExpectTheFrameAndFilledBars(window);
  if (window.empty()) return;
  cv::Mat green;
  cv::inRange(window(cv::Rect(0, 0, 640, 480)), cv::Scalar(40, 200, 40), cv::Scalar(80, 240, 80), green);
  EXPECT_GT(cv::countNonZero(green), 400) << "the board found is not outlined";
}

}  // namespace
}  // namespace arview
