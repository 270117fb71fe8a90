// `arview view` in a real X session: a virtual X server (Xvfb, started here), the view window,
// and xdotool driving the mouse and keys as a user would. Also the headless orbit and the
// no-display message. Xvfb and xdotool come from scripts/install-deps.sh.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tests/support/run_command.h"
#include "tests/support/test_data.h"
#include "tests/support/virtual_display.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::Child;
using testing::RunArview;
using testing::Shell;
using testing::VirtualDisplay;

constexpr double kDegPerPixel = 0.4;  // app/view/view_camera.h OrbitCamera::kDegPerPixel

std::string FoxScene(const fs::path& dir) {
  const fs::path scene = dir / "fox.yaml";
  std::ofstream(scene) << "# The Fox with four keys: three look-at keys and its walk behind it.\n"
                          "characters:\n"
                          "  - name: fox\n"
                          "    asset: \"" << testing::SharedData("characters/Fox/glTF-Binary/Fox.glb").string() << "\"\n"
                          "    scale: 0.01\n"
                          "    keys:\n"
                          "      - azimuth: 0\n"
                          "        generate: lookat\n"
                          "      - azimuth: 90\n"
                          "        generate: lookat\n"
                          "      - azimuth: 180\n"
                          "        clip: Walk\n"
                          "      - azimuth: -90\n"
                          "        generate: lookat\n";
  return scene.string();
}

std::vector<json> JsonLines(const std::string& text) {
  std::vector<json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] != '{' || in.eof()) continue;  // a line still being written has no newline yet
    lines.push_back(json::parse(line));
  }
  return lines;
}

// Waits until `file` holds `count` state lines (the 'p' key's).
bool WaitForStates(const std::string& file, size_t count, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    if (JsonLines(testing::ReadWholeFile(file)).size() >= count) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

Eigen::Vector3d Vec(const json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / M_PI;
}

// The key weights `arview anim weights` gives for a viewpoint.
std::vector<double> AnimWeights(const std::string& scene, const Eigen::Vector3d& v) {
  char text[128];
  std::snprintf(text, sizeof text, "%.17g,%.17g,%.17g", v.x(), v.y(), v.z());
  const auto r = RunArview({"anim", "weights", "--scene", scene, "--viewpoint", text, "--json"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::vector<double> w;
  if (r.exit_code != 0) return w;
  const json parsed = json::parse(r.out);
  EXPECT_TRUE(parsed.contains("keys")) << text << ": " << r.out;
  for (const json& k : parsed["keys"]) w.push_back(k["weight"].get<double>());
  return w;
}

class ViewWindowTest : public testing::XSessionTest<::testing::Test> {
 protected:
  void SetUp() override {
    StartXSession("view");
    if (HasFatalFailure() || IsSkipped()) return;
    ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"), "../shared/data");
  }
};

// The procedure: drag, check the weights against `arview anim weights`, add a key with
// a key press, save, check the file; the screenshot of the window with the overlay is taken
// on the way (to $ARVIEW_VIEW_SCREENSHOT when set, e.g. docs/view_overlay.png).
TEST_F(ViewWindowTest, DragMovesTheViewpointAndAKeyPressAddsASavedKey) {
  const std::string scene = FoxScene(dir_);
  const std::string original = (dir_ / "original.yaml").string();  // the scene before the save
  fs::copy_file(scene, original);
  const std::string out = (dir_ / "view.out").string();
  const char* bin = std::getenv("ARVIEW_BIN");
  ::setenv("DISPLAY", display_->name().c_str(), 1);
  Child view({bin ? bin : "arview", "view", "--scene", scene, "--fps-limit", "30", "--seconds", "240", "--json"}, out);
  const std::string d = display_->name();
  Shell("timeout 120 xdotool search --sync --name '^arview view'", d);
  // The window is up; keys go to the window under the pointer (no window manager runs). 'p'
  // prints the state after the next frame: waiting for it also waits for the scene to load.
  Shell("xdotool mousemove 640 360 sleep 0.3 key p", d);
  ASSERT_TRUE(WaitForStates(out, 1, 120)) << testing::ReadWholeFile(out);
  // Drag 100 px right and 20 px up with the left button: orbit.
  Shell("xdotool mousedown 1 sleep 0.2 mousemove 690 350 sleep 0.2 mousemove 740 340 sleep 0.2 mouseup 1 sleep 0.3 key p", d);
  ASSERT_TRUE(WaitForStates(out, 2, 60)) << testing::ReadWholeFile(out);
  // Add a key here (a: the selection, by default the asset's first clip), save it, print again.
  Shell("xdotool key a sleep 0.3 key s sleep 0.3 key p", d);
  ASSERT_TRUE(WaitForStates(out, 3, 60)) << testing::ReadWholeFile(out);
  const char* shot_env = std::getenv("ARVIEW_VIEW_SCREENSHOT");
  const std::string shot = shot_env && *shot_env ? shot_env : (dir_ / "overlay.png").string();
  Shell("ffmpeg -loglevel error -y -f x11grab -video_size 1280x720 -i " + d + " -frames:v 1 " + testing::ShellQuote(shot), d);
  Shell("xdotool key q", d);
  ASSERT_EQ(view.Wait(60), 0) << testing::ReadWholeFile(out);

  const std::vector<json> states = JsonLines(testing::ReadWholeFile(out));
  ASSERT_EQ(states.size(), 4u) << testing::ReadWholeFile(out);  // three 'p' and the final --json
  const json& before = states[0];
  const json& after = states[1];
  EXPECT_NEAR(before["camera"]["azimuth_deg"].get<double>(), 30, 1e-9);
  EXPECT_NEAR(before["camera"]["elevation_deg"].get<double>(), 15, 1e-9);
  // The drag: +100 px right orbits 40° the other way, 20 px up lowers the camera by 8°.
  EXPECT_NEAR(after["camera"]["azimuth_deg"].get<double>(), 30 - 100 * kDegPerPixel, 1e-9);
  EXPECT_NEAR(after["camera"]["elevation_deg"].get<double>(), 15 - 20 * kDegPerPixel, 1e-9);
  const Eigen::Vector3d v0 = Vec(before["viewpoint"]), v1 = Vec(after["viewpoint"]);
  EXPECT_GT(AngleDeg(v0, v1), 30);
  EXPECT_NEAR(after["viewpoint_azimuth_deg"].get<double>(), -10, 1e-6);  // the target is above the feet

  // The weights the window used are those `arview anim weights` gives for that viewpoint.
  for (const json* state : {&before, &after}) {
    const std::vector<double> expected = AnimWeights(original, Vec((*state)["viewpoint"]));
    ASSERT_EQ(expected.size(), 4u);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR((*state)["keys"][k]["weight"].get<double>(), expected[k], 1e-9) << k;
  }
  double changed = 0;
  for (int k = 0; k < 4; ++k) changed += std::abs(after["keys"][k]["weight"].get<double>() - before["keys"][k]["weight"].get<double>());
  EXPECT_GT(changed, 0.1) << "the drag changes the weights";

  // The key press added a fifth key at the dragged viewpoint, and the saved scene has it.
  const json& saved = states[2];
  ASSERT_EQ(saved["keys"].size(), 5u);
  EXPECT_FALSE(saved["unsaved"].get<bool>()) << saved["message"];
  EXPECT_EQ(saved["keys"][4]["plays"], "Survey");
  EXPECT_LT(AngleDeg(Vec(saved["keys"][4]["viewpoint"]), v1), 0.02);  // rounded to 0.01°
  const std::string text = testing::ReadWholeFile(scene);
  EXPECT_NE(text.find("# The Fox with four keys"), std::string::npos) << "the rest of the file is kept";
  EXPECT_NE(text.find("clip: \"Survey\""), std::string::npos) << text;
  const std::vector<double> w = AnimWeights(scene, v1);
  ASSERT_EQ(w.size(), 5u) << "the saved scene loads with its five keys";
  EXPECT_GT(w[4], 0.99) << "the viewpoint sits on the new key";

  const cv::Mat image = cv::imread(shot);
  ASSERT_EQ(image.cols, 1280);
  ASSERT_EQ(image.rows, 720);
  std::cout << "[view] screenshot " << shot << "\n";
}

TEST(View, HeadlessOrbitWritesEveryFrame) {
  ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"), "../shared/data");
  const fs::path dir = fs::temp_directory_path() / ("arview_view_orbit_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = FoxScene(dir);
  const auto r = RunArview({"view", "--scene", scene, "--orbit", "azimuth=0..90,elevation=20,seconds=1", "--fps", "12",
                            "--size", "320x240", "--out", (dir / "orbit.mp4").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  cv::VideoCapture video((dir / "orbit.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  cv::Mat first, last;
  for (cv::Mat f; video.read(f); ++frames) {
    EXPECT_EQ(f.size(), cv::Size(320, 240));
    if (frames == 0) first = f.clone();
    last = f.clone();
  }
  EXPECT_EQ(frames, 12);
  EXPECT_GT(cv::norm(first, last, cv::NORM_L1), 1e5) << "the camera moved";
  EXPECT_FALSE(fs::exists(dir / "orbit.partial.mp4"));
  fs::remove_all(dir);
}

TEST(View, WithoutADisplayOneLineSaysSo) {
  ARVIEW_REQUIRE_DATA_PATH(testing::SharedData("characters/Fox/glTF-Binary/Fox.glb"), "../shared/data");
  const fs::path dir = fs::temp_directory_path() / ("arview_view_nodisplay_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string scene = FoxScene(dir);
  const char* previous = std::getenv("DISPLAY");
  const std::string saved = previous ? previous : "";
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  const auto r = RunArview({"view", "--scene", scene});
  if (previous) ::setenv("DISPLAY", saved.c_str(), 1);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(testing::LineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no display (DISPLAY is not set)"), std::string::npos) << r.err;
  const auto bad = RunArview({"view", "--scene", scene, "--orbit", "speed=2", "--out", (dir / "o.mp4").string()});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(testing::LineCount(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("--orbit: unknown field 'speed'"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "o.mp4"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview
