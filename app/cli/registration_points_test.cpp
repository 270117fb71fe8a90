#include "app/cli/registration_points.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "base/error.h"
#include "synth/synth_room.h"
#include "tests/support/test_data.h"

namespace arview::app {
namespace {

namespace fs = std::filesystem;

TEST(RegistrationPoints, TheAnchorAndTheRestBoxsCornersInTheMap) {
  anim::Character c;
  c.meshes.emplace_back();
  c.meshes[0].positions = {{-0.2f, 0, -0.1f}, {0.2f, 1.8f, 0.1f}, {0, 0.9f, 0}};
  anim::Placement placement;
  placement.anchor.position = {1, 2, 0};
  placement.anchor.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));  // +Y up → +Z
  placement.anchor.scale = 0.5;
  const std::vector<Eigen::Vector3d> marks = CharacterMarks(c, placement);
  ASSERT_EQ(marks.size(), 9u);
  EXPECT_EQ(marks[0], Eigen::Vector3d(1, 2, 0));
  double top = -1e9, bottom = 1e9;
  for (size_t i = 1; i < marks.size(); ++i) top = std::max(top, marks[i].z()), bottom = std::min(bottom, marks[i].z());
  EXPECT_NEAR(bottom, 0.0, 1e-6);
  EXPECT_NEAR(top, 0.9, 1e-6);  // 1.8 tall at half scale, standing up along +Z
  EXPECT_THROW(CharacterMarks(anim::Character{}, placement), Error);
}

TEST(RegistrationPoints, APointsFileIsThreeNumbersALineAndNamesTheLineItRefuses) {
  const fs::path file = fs::temp_directory_path() / ("arview_points_" + std::to_string(::getpid()) + ".txt");
  std::ofstream(file) << "# anchor\n0 0 0\n\n 1.5 -2 3e-1  # a corner\n";
  const std::vector<Eigen::Vector3d> points = ReadPointsFile(file);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[1], Eigen::Vector3d(1.5, -2, 0.3));
  std::ofstream(file) << "0 0 0\n1 2\n";
  try {
    ReadPointsFile(file);
    FAIL() << "a line of two numbers was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ":2: expected three numbers"), std::string::npos) << e.what();
  }
  std::ofstream(file) << "# nothing\n";
  EXPECT_THROW(ReadPointsFile(file), Error);
  fs::remove(file);
}

TEST(RegistrationPoints, TheRoomsTrueSurfacesOnlyForARenderedRoom) {
  const fs::path file = fs::temp_directory_path() / ("arview_room_gt_" + std::to_string(::getpid()) + ".txt");
  std::ofstream(file) << "# timestamp tx ty tz qx qy qz qw\n0 0 0 0 0 0 0 1\n";
  try {
    RoomGeometryPoints(file, synth::kOpenCvDocData);
    FAIL() << "a ground truth not made by synth room was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not the ground truth of a room rendered by 'arview synth room'"),
              std::string::npos)
        << e.what();
  }
  ARVIEW_REQUIRE_DATA_PATH(fs::path(synth::kOpenCvDocData) / "building.jpg", "Debian package opencv-doc");
  std::ofstream(file) << "# arview synth room, seed 1, window light, world: metres, z up, floor z = 0\n";
  const std::vector<Eigen::Vector3d> points = RoomGeometryPoints(file, synth::kOpenCvDocData);
  const size_t panels = synth::MakeRoomScene(synth::kOpenCvDocData, synth::SynthLighting::kWindow).panels.size();
  EXPECT_EQ(points.size(), 9 * panels);  // 4 corners, 4 edge midpoints, the centre
  for (const Eigen::Vector3d& p : points) {
    EXPECT_LE(std::abs(p.x()), 3.5 + 1e-9);
    EXPECT_LE(std::abs(p.y()), 2.5 + 1e-9);
    EXPECT_GE(p.z(), -1e-9);
    EXPECT_LE(p.z(), 2.8 + 1e-9);
  }
  fs::remove(file);
}

}  // namespace
}  // namespace arview::app
