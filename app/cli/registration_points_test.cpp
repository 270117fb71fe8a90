#include "app/cli/registration_points.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "base/error.h"

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

}  // namespace
}  // namespace arview::app
