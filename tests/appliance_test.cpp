// The appliance end to end on real data: templeRing mapped from its even frames, a character
// placed on the temple's base, the odd frames replayed through the whole pipeline.

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include <opencv2/videoio.hpp>

#include "tests/support/run_command.h"
#include "tests/support/test_data.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::RunArview;

TEST(Appliance, TempleRingReplayCompositesEveryFrameAndTheHeadFollowsTheCamera) {
  const fs::path temple = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(temple, "../shared/data");
  ARVIEW_REQUIRE_DATA_PATH("/usr/share/assimp/models/X/BCN_Epileptic.X", "Debian package assimp-testmodels");
  const fs::path dir = fs::temp_directory_path() / ("arview_appliance_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);

  auto run = [](const std::vector<std::string>& args) {
    const auto r = RunArview(args);
    EXPECT_EQ(r.exit_code, 0) << args[0] << ": " << r.err;
    return r;
  };
  run({"import", "middlebury", temple.string(), "--out", (dir / "temple").string()});
  run({"map", (dir / "temple").string(), "--out", (dir / "map").string(), "--frames", "0-46:2"});
  run({"place", (dir / "map").string(), "--character", "/usr/share/assimp/models/X/BCN_Epileptic.X", "--base-clip",
       "rest", "--height", "0.2", "--out", (dir / "scene.yaml").string()});
  const auto replay = run({"replay", (dir / "temple").string(), "--map", (dir / "map").string(), "--scene",
                           (dir / "scene.yaml").string(), "--frames", "1-46:2", "--out", (dir / "out.mp4").string(),
                           "--stats", (dir / "stats.json").string(), "--trajectory", (dir / "traj.txt").string()});
  if (HasFailure()) return;

  std::cout << replay.out;
  cv::VideoCapture video((dir / "out.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  for (cv::Mat f; video.read(f);) ++frames;
  EXPECT_EQ(frames, 23) << "every odd frame composited";
  EXPECT_FALSE(fs::exists(dir / "out.partial.mp4"));

  const std::string stats = testing::ReadWholeFile((dir / "stats.json").string());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("frames_processed": (\d+))")));
  EXPECT_EQ(std::stoi(m[1]), 23);
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("frames_localized": (\d+))")));
  EXPECT_EQ(std::stoi(m[1]), 23);
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("frames_within_20_deg": (\d+))")));
  EXPECT_EQ(std::stoi(m[1]), 23) << "the blended head's forward axis within 20 deg of the camera centre";
  ASSERT_TRUE(std::regex_search(stats, m, std::regex(R"("max_error_deg": ([0-9.]+))")));
  EXPECT_LE(std::stod(m[1]), 20.0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview
