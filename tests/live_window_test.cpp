// The live window as a person meets it (issue 35): `arview replay --out window` and `arview run
// --out window` in a real X session (Xvfb), frames appearing in the window, and each way of
// ending it (Esc, q, Ctrl-C, SIGTERM) ending the session promptly with the report, the stats
// and the trajectory written. The window used to freeze on its first frame (highgui shown from
// the sink's thread); only the no-display error was tested then.
//
// Inputs stay small: the 60-frame rendered room of the cancellation tests (made once per machine
// with `arview synth room`) with a synthetic map (random points: every frame is lost, so the
// window shows the video alone, but every stage runs), and for `run` the emulated camera
// (tests/support/fake_v4l2_device.cpp) with a synthetic map of its size.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/camera.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/random_map.h"
#include "tests/support/run_command.h"
#include "tests/support/test_data.h"
#include "tests/support/virtual_display.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::Child;
using testing::ReadWholeFile;
using testing::Shell;
using testing::ShellQuote;
using testing::VirtualDisplay;

constexpr int kRoomFrames = 60;

enum class Ending { kEscape, kQ, kSigint, kSigterm };
enum class Input { kReplay, kCamera };

struct Case {
  Input input;
  Ending ending;
};

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  const char* input = info.param.input == Input::kReplay ? "Replay" : "Run";
  const char* ending[] = {"Escape", "Q", "Sigint", "Sigterm"};
  return std::string(input) + "EndedBy" + ending[static_cast<int>(info.param.ending)];
}

// The rendered room, shared with the cancellation tests (same name: made once per machine).
fs::path SharedRoom() {
  const fs::path room = fs::temp_directory_path() /
                        ("arview_cancellation_room_" + std::to_string(::getuid()) + "_" + std::to_string(kRoomFrames));
  if (fs::exists(room / "frames.txt")) return room;
  const fs::path rendering = room.string() + ".rendering_" + std::to_string(::getpid());
  const auto r = testing::RunArview(
      {"synth", "room", "--out", rendering.string(), "--frames", std::to_string(kRoomFrames), "--seed", "1", "--quiet"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::error_code ec;
  fs::rename(rendering, room, ec);  // fails harmlessly when a parallel test got there first
  fs::remove_all(rendering, ec);
  return room;
}

class LiveWindow : public testing::XSessionTest<::testing::TestWithParam<Case>> {
 protected:
  void SetUp() override {
    // The room first (rendered once per machine, a minute), then the display: no X server
    // waits idle meanwhile.
    if (GetParam().input == Input::kReplay && fs::exists("/usr/share/doc/opencv-doc/examples/data/left01.jpg")) SharedRoom();
    StartXSession("live_window");
  }

  // The command line (through `sh -c 'exec ...'`, so that the child's pid is arview's) and the
  // size of the window it opens.
  std::vector<std::string> Command(Input input, cv::Size& window) {
    const char* bin_env = std::getenv("ARVIEW_BIN");
    const std::string bin = bin_env ? bin_env : "arview";
    const std::string outputs = " --out window --stats " + ShellQuote((dir_ / "stats.json").string()) +
                                " --trajectory " + ShellQuote((dir_ / "trajectory.txt").string());
    std::string line;
    if (input == Input::kReplay) {
      const fs::path room = SharedRoom();
      const calib::Camera camera = calib::LoadCamera(room / "camera.yaml");
      testing::WriteRandomMap(camera, dir_ / "map");
      window = camera.Size();
      // Looped and paced: it runs until it is ended, as a camera would.
      line = "exec " + ShellQuote(bin) + " replay " + ShellQuote(room.string()) + " --map " +
             ShellQuote((dir_ / "map").string()) + " --paced --loop 1000" + outputs;
    } else {
      // The emulated camera: 64x48 frames at 30 per second.
      const calib::Camera camera = calib::Camera::Pinhole(64, 48, 60, 60, 32, 24);
      testing::WriteRandomMap(camera, dir_ / "map");
      window = camera.Size();
      // The preloaded camera comes before AddressSanitizer's runtime in the asan preset's build.
      line = "exec env LD_PRELOAD=" + ShellQuote(ARVIEW_FAKE_V4L2_LIBRARY) +
             " ASAN_OPTIONS=\"$ASAN_OPTIONS:verify_asan_link_order=0\" " + ShellQuote(bin) +
             " run --device /dev/video-arview-fake --map " + ShellQuote((dir_ / "map").string()) + outputs;
    }
    line += " 2>" + ShellQuote((dir_ / "stderr.txt").string());
    return {"sh", "-c", line};
  }
};

TEST_P(LiveWindow, ShowsFramesAndEndsPromptlyWithItsOutputs) {
  const Case c = GetParam();
  if (c.input == Input::kReplay) {
    ARVIEW_REQUIRE_DATA_PATH("/usr/share/doc/opencv-doc/examples/data/left01.jpg", "Debian package opencv-doc");
  }
  ::setenv("DISPLAY", display_->name().c_str(), 1);
  cv::Size window;
  const std::vector<std::string> command = Command(c.input, window);
  const fs::path out = dir_ / "stdout.txt";
  Child app(command, out.string());
  const std::string id = WaitForLiveWindow(app);
  ASSERT_FALSE(id.empty()) << "no window with a live status appeared\n" << ReadWholeFile((dir_ / "stderr.txt").string());
  // Let it run a little, then look at what the window shows (no window manager: it sits at 0,0).
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const fs::path shot = dir_ / "window.png";
  Shell("ffmpeg -loglevel error -y -f x11grab -video_size 1280x720 -i " + display_->name() + " -frames:v 1 " +
            ShellQuote(shot.string()),
        display_->name());
  const cv::Mat screen = cv::imread(shot.string());
  ASSERT_FALSE(screen.empty());
  cv::Scalar mean, stddev;
  cv::meanStdDev(screen(cv::Rect({0, 0}, window)), mean, stddev);
  // The room's video (textured walls) or the emulated camera's mid-grey, not a blank window.
  if (c.input == Input::kReplay) {
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30) << "the window shows no picture";
  } else {
    EXPECT_NEAR(mean[0], 128, 20) << "the window does not show the camera's grey";
  }
  const std::string title = Shell("xdotool getwindowname " + id, display_->name());
  EXPECT_TRUE(std::regex_search(title, std::regex(R"(\d+\.\d fps, latency \d+ ms, \d+ dropped)"))) << title;

  const auto signalled = std::chrono::steady_clock::now();
  // xdotool's exit status is not checked for a key: the window may be gone before xdotool's own
  // request after the key (BadWindow, exit 1, seen once in CI with the session ended in 75 ms);
  // whether the key ended the session is what the checks below see.
  const std::string xdotool = "DISPLAY=" + display_->name() + " xdotool key --window " + id;
  switch (c.ending) {
    case Ending::kEscape: (void)std::system((xdotool + " Escape >/dev/null 2>&1").c_str()); break;
    case Ending::kQ: (void)std::system((xdotool + " q >/dev/null 2>&1").c_str()); break;
    case Ending::kSigint: ::kill(app.pid(), SIGINT); break;
    case Ending::kSigterm: ::kill(app.pid(), SIGTERM); break;
  }
  const int status = app.Wait(10);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count();
  ASSERT_GE(status, 0) << "still running 10 s after it was asked to end";
  std::printf("[live window] %s ended %.3f s after it was asked\n", CaseName({c, 0}).c_str(), seconds);
  // Issue 35 asks 0.5 s; the bound here leaves room for a machine running other tests.
  EXPECT_LT(seconds, 1.5 * testing::kSanitizerSlowdown);
  const std::string report = ReadWholeFile(out.string());
  EXPECT_EQ(status, 0) << report << ReadWholeFile((dir_ / "stderr.txt").string());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(report, m, std::regex(R"(frames: \d+ read, (\d+) processed)"))) << report;
  EXPECT_GE(std::stoi(m[1]), 2) << report;  // few on a busy machine: every lost frame relocalizes
  EXPECT_NE(report.find("latency, capture to output: median"), std::string::npos) << report;
  const nlohmann::json stats = nlohmann::json::parse(ReadWholeFile((dir_ / "stats.json").string()));
  EXPECT_EQ(stats["frames"].size(), stats["frames_processed"].get<size_t>());
  EXPECT_GT(stats["frames"][0]["latency_ms"].get<double>(), 0);
  EXPECT_TRUE(fs::exists(dir_ / "trajectory.txt"));
}

INSTANTIATE_TEST_SUITE_P(EachWayToEnd, LiveWindow,
                         ::testing::Values(Case{Input::kReplay, Ending::kEscape}, Case{Input::kReplay, Ending::kQ},
                                           Case{Input::kReplay, Ending::kSigint}, Case{Input::kReplay, Ending::kSigterm},
                                           Case{Input::kCamera, Ending::kEscape}, Case{Input::kCamera, Ending::kSigint},
                                           Case{Input::kCamera, Ending::kSigterm}),
                         CaseName);

}  // namespace
}  // namespace arview

namespace arview {
namespace {

class WindowPlacement : public testing::XSessionTest<::testing::Test> {
 protected:
  void SetUp() override {
    StartXSession("window_placement");
    if (HasFatalFailure() || IsSkipped()) return;
    ARVIEW_REQUIRE_DATA_PATH("/usr/share/doc/opencv-doc/examples/data/left01.jpg", "Debian package opencv-doc");
    room_ = SharedRoom();
    testing::WriteRandomMap(calib::LoadCamera(room_ / "camera.yaml"), dir_ / "map");
    ::setenv("DISPLAY", display_->name().c_str(), 1);
  }
  testing::CommandResult Replay(const std::vector<std::string>& placement) {
    std::vector<std::string> args = {"replay", room_.string(), "--map", (dir_ / "map").string(), "--frames", "0-9",
                                     "--out", "window"};
    args.insert(args.end(), placement.begin(), placement.end());
    return testing::RunArview(args);
  }
  fs::path room_;
};

// A headset's panel is a display output: the window opens at its corner (Xvfb has one output,
// "screen"), and an output that is not there is one line naming those that are.
TEST_F(WindowPlacement, OpensOnANamedOutputAndNamesTheOutputsWhenItIsNotThere) {
  const auto placed = Replay({"--window-output", "screen", "--fullscreen"});
  ASSERT_EQ(placed.exit_code, 0) << placed.err;
  EXPECT_NE(placed.out.find("shown in window \"arview\""), std::string::npos) << placed.out;
  EXPECT_NE(placed.out.find("at screen (1280x720+0+0), fullscreen"), std::string::npos) << placed.out;
  const auto missing = Replay({"--window-output", "HDMI-9"});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_EQ(testing::LineCount(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("no connected output 'HDMI-9' (connected: screen 1280x720+0+0)"), std::string::npos)
      << missing.err;
}

}  // namespace
}  // namespace arview

namespace arview {
namespace {

// The animation's clock starts at the session's first frame. A camera stamps frames with the
// machine's uptime and an imported dataset (TUM) with Unix times; the idle layers build their
// motion from time 0 up to the first time they are asked for, so before, the first frame of such
// a replay built decades of idle motion (hours of work) and a camera's first frame paid 1 s per
// 7 h of uptime. The same frames stamped from 0 and from 1.7e9 s must animate alike.
TEST(AnimationClock, ARecordingStampedWithUnixTimesAnimatesAsOneStampedFromZero) {
  ARVIEW_REQUIRE_DATA_PATH("/usr/share/doc/opencv-doc/examples/data/left01.jpg", "Debian package opencv-doc");
  const fs::path room = SharedRoom();
  const fs::path dir = fs::temp_directory_path() / ("arview_animation_clock_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  constexpr int kFrames = 12;
  constexpr double kUnixTime = 1.7e9;
  for (const auto& [name, offset] : {std::pair<std::string, double>{"zero", 0.0}, {"unix", kUnixTime}}) {
    fs::create_directories(dir / name / "frames");
    fs::copy_file(room / "camera.yaml", dir / name / "camera.yaml");
    std::ofstream list(dir / name / "frames.txt");
    list << "# timestamp path\n";
    for (int i = 0; i < kFrames; ++i) {
      char file[32];
      std::snprintf(file, sizeof file, "%06d.png", i);
      fs::copy_file(room / "frames" / file, dir / name / "frames" / file);
      list << std::fixed << offset + i / 30.0 << " frames/" << file << "\n";
    }
  }
  testing::WriteRandomMap(calib::LoadCamera(room / "camera.yaml"), dir / "map");
  std::ofstream(dir / "scene.yaml") << "characters:\n  - name: figure\n    asset: builtin:figure\n    anchor:\n"
                                       "      position: [0, 0, 0]\n      rotation_deg: [90, 0, 0]\n    keys:\n"
                                       "      - viewpoint: [0, 0, 1]\n        clip: Idle\n";
  std::vector<nlohmann::json> stats;
  for (const std::string name : {"zero", "unix"}) {
    const auto r = testing::RunArview({"replay", (dir / name).string(), "--map", (dir / "map").string(), "--scene",
                                       (dir / "scene.yaml").string(), "--out", "null", "--stats",
                                       (dir / (name + ".json")).string()});
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
    stats.push_back(nlohmann::json::parse(ReadWholeFile((dir / (name + ".json")).string())));
  }
  ASSERT_EQ(stats[0]["frames"].size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(stats[1]["frames"].size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(stats[0]["frames"][i]["idle_weight"], stats[1]["frames"][i]["idle_weight"]) << "frame " << i;
    // The figure has eyes (anim/gaze.h): every frame says whether they were on the viewer, the
    // same on both clocks.
    ASSERT_TRUE(stats[0]["frames"][i].contains("eyes_on_viewer")) << "frame " << i;
    EXPECT_EQ(stats[0]["frames"][i]["eyes_on_viewer"], stats[1]["frames"][i]["eyes_on_viewer"]) << "frame " << i;
    EXPECT_EQ(stats[0]["frames"][i]["blinking"], stats[1]["frames"][i]["blinking"]) << "frame " << i;
  }
  EXPECT_EQ(stats[0]["eyes"]["frames"].get<int>(), kFrames) << stats[0]["eyes"];
  EXPECT_EQ(stats[0]["eyes"], stats[1]["eyes"]);
  // Building 1.7e9 s of idle motion took far longer than this; from the first frame it is nothing.
  EXPECT_LT(stats[1]["stages"]["animate"]["max_ms"].get<double>(), 1000.0) << stats[1]["stages"]["animate"];
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview
