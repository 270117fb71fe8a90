// The first run without a scene (issue 56): `arview replay` and `arview run` without --scene
// stand the built-in figure on the map's floor in front of the first localized view, say so in
// one line with the `arview place` command that writes the same scene; --no-figure keeps the
// video and the tracking alone; a map without a floor is one note and the session goes on. The
// map: the graffiti plane (tests/support/graffiti_map.h), which its cameras look down on.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "anim_authoring/scene.h"
#include "map/map_file.h"
#include "recordings/trajectory.h"
#include "tests/support/emulated_camera.h"
#include "tests/support/graffiti_map.h"
#include "tests/support/run_command.h"
#include "tests/support/test_data.h"
#include "tracker/test_planar_scene.h"

namespace arview {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;

// "no --scene: the built-in figure stands on the floor of <map> at (x, y, z) ...; to keep it:
// arview place <map> --character builtin:figure --at x,y,z --facing x,y,z --out scene.yaml"
const std::regex kPlacedLine(
    R"(no --scene: the built-in figure stands on the floor of (\S+) at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\) (m|map units), )"
    R"([\d.]+ (m|map units) along the floor in front of the first localized view \(placed in [\d.]+ ms\); to keep it: )"
    R"(arview place (\S+) --character builtin:figure --at (\S+) --facing ([-\d.]+),([-\d.]+),([-\d.]+) --out scene.yaml)");
// The groups of kPlacedLine.
enum Group { kMap = 1, kX, kY, kZ, kUnit, kUnitAlong, kPlaceMap, kAt, kFacingX, kFacingY, kFacingZ };

class FirstRun : public ::testing::Test {
 protected:
  void SetUp() override {
    ARVIEW_REQUIRE_DATA_PATH(tracker::testing::kGraffitiTexture, "Debian package opencv-doc");
    dir_ = fs::temp_directory_path() / ("arview_first_run_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ::setenv("ARVIEW_CACHE_DIR", (dir_ / "cache").c_str(), 1);
    testing::WriteGraffitiMapFolder(dir_ / "map");
    testing::WriteGraffitiViews(dir_ / "views");
  }
  void TearDown() override {
    ::unsetenv("ARVIEW_CACHE_DIR");
    if (!HasFailure()) fs::remove_all(dir_);
  }

  CommandResult Replay(std::vector<std::string> extra) {
    std::vector<std::string> args = {"replay", (dir_ / "views").string(), "--map", (dir_ / "map").string(), "--out", "null"};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunArview(args);
  }

  fs::path dir_;
};

TEST_F(FirstRun, ReplayStandsTheFigureInFrontOfTheFirstLocalizedViewAndPlaceKeepsIt) {
  const fs::path trajectory = dir_ / "replay.txt";
  const CommandResult r = Replay({"--trajectory", trajectory.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, kPlacedLine)) << r.err;
  EXPECT_EQ(m[kMap].str(), (dir_ / "map").string());
  EXPECT_EQ(m[kPlaceMap].str(), (dir_ / "map").string());
  const Eigen::Vector3d at(std::stod(m[kX].str()), std::stod(m[kY].str()), std::stod(m[kZ].str()));
  const std::string facing_text = m[kFacingX].str() + "," + m[kFacingY].str() + "," + m[kFacingZ].str();
  const Eigen::Vector3d facing(std::stod(m[kFacingX].str()), std::stod(m[kFacingY].str()), std::stod(m[kFacingZ].str()));
  EXPECT_EQ(m[kAt].str(), m[kX].str() + "," + m[kY].str() + "," + m[kZ].str());
  // On the graffiti (world z = 0), facing the first localized view's camera.
  EXPECT_NEAR(at.z(), 0, 0.005);
  const recordings::Trajectory poses = recordings::ReadTum(trajectory);
  ASSERT_FALSE(poses.empty());
  EXPECT_LT((poses.front().pose.Center() - facing).norm(), 1e-3) << "the first localized frame's camera";
  EXPECT_GT(poses.front().pose.ToCamera(at).z(), 0) << "in front of the camera";

  // The printed command writes the scene whose character stands there, facing the same way.
  const fs::path scene = dir_ / "scene.yaml";
  const CommandResult place = testing::RunArview({"place", (dir_ / "map").string(), "--character", "builtin:figure",
                                                  "--at", m[kAt].str(), "--facing", facing_text, "--out", scene.string(),
                                                  "--no-light"});
  ASSERT_EQ(place.exit_code, 0) << place.err;
  const authoring::Scene placed = authoring::LoadScene(scene);
  ASSERT_EQ(placed.characters.size(), 1u);
  const Anchor& anchor = placed.characters[0].anchor;
  EXPECT_LT((anchor.position - at).norm(), 2e-4);
  const Eigen::Vector3d forward = anchor.rotation * Eigen::Vector3d::UnitZ();
  Eigen::Vector3d to_camera = facing - anchor.position;
  const Eigen::Vector3d up = anchor.rotation * Eigen::Vector3d::UnitY();
  to_camera -= to_camera.dot(up) * up;
  EXPECT_GT(forward.dot(to_camera.normalized()), 0.9999);
}

TEST_F(FirstRun, NoFigureKeepsTheVideoAndTheTrackingAlone) {
  const CommandResult r = Replay({"--no-figure"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("built-in figure"), std::string::npos) << r.err;
  const CommandResult both = Replay({"--no-figure", "--scene", (dir_ / "scene.yaml").string()});
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.err.find("arview: --no-figure is for a session without --scene"), std::string::npos) << both.err;
}

// A map whose points cannot hold a floor: one note, and the session goes on without a character.
TEST_F(FirstRun, AMapWithoutAFloorIsOneNoteAndTheSessionGoesOn) {
  map::Map map = map::LoadMap(dir_ / "map");
  for (size_t i = 0; i < map.points.size(); ++i) map.points[i].xyz = Eigen::Vector3d(0.001 * static_cast<double>(i), 0, 0);
  map::SaveMap(map, dir_ / "map" / map::kMapFileName);
  const CommandResult r = Replay({});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("note: no --scene, and " + (dir_ / "map").string() +
                       " has no floor for the built-in figure (the map's points cannot hold a floor: "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("the session goes on with the video and the tracking only"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("no --scene: the built-in figure stands"), std::string::npos) << r.err;
}

// `arview run` on the emulated camera playing the views: the same line, once.
TEST_F(FirstRun, RunStandsTheFigureOnceOnTheLiveCamera) {
  ASSERT_TRUE(fs::exists(ARVIEW_FAKE_V4L2_LIBRARY)) << ARVIEW_FAKE_V4L2_LIBRARY;
  const CommandResult live = testing::RunWithEmulatedCamera(
      {"run", "--device", testing::kEmulatedCamera, "--map", (dir_ / "map").string(), "--out", "null"},
      {{"ARVIEW_FAKE_CAMERA_RECORDING", (dir_ / "views").string()}}, dir_, {0, 0}, 2.0 * testing::kSanitizerSlowdown, {},
      "no --scene: the built-in figure stands");  // Ctrl-C 2 s of frames after the first localized view's line
  EXPECT_EQ(live.exit_code, 0) << live.err;
  const auto lines = std::distance(std::sregex_iterator(live.err.begin(), live.err.end(), kPlacedLine), std::sregex_iterator());
  EXPECT_EQ(lines, 1) << live.err;
}

}  // namespace
}  // namespace arview
