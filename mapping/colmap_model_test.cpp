// COLMAP's binary model read by ReadColmapMap, on a small model written by the test (the fuzz
// targets' fixture): values that are not numbers are refused naming the file, the record and
// the value (issue 41).

#include "mapping/colmap_model.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>

#include "fuzz/colmap_fixture.h"
#include "map/map_file.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The fixture's layout (fuzz/colmap_fixture.h SmallColmapModel): the byte offsets of the values
// the tests overwrite.
constexpr std::size_t kImageNameBytes = sizeof("frames/000001.png");  // with its NUL
constexpr std::size_t kImageHeaderBytes = 4 + 7 * 8 + 4 + kImageNameBytes + 8;
constexpr std::size_t kImageBytes = kImageHeaderBytes + 3 * 24;
// Image `image` (0 or 1), 2D point `point`'s x (y is 8 bytes on).
constexpr std::size_t ImagePointX(std::size_t image, std::size_t point) {
  return 8 + image * kImageBytes + kImageHeaderBytes + point * 24;
}
// The image's translation x (after the id and the quaternion).
constexpr std::size_t ImageTranslationX(std::size_t image) { return 8 + image * kImageBytes + 4 + 4 * 8; }
// The one camera's parameter k (after the count, id, model, width and height).
constexpr std::size_t CameraParameter(std::size_t k) { return 8 + 4 + 4 + 8 + 8 + k * 8; }
// 3D point p's (0-based) z and error.
constexpr std::size_t kPointBytes = 8 + 24 + 3 + 8 + 8 + 2 * 8;
constexpr std::size_t PointZ(std::size_t p) { return 8 + p * kPointBytes + 8 + 16; }
constexpr std::size_t PointError(std::size_t p) { return 8 + p * kPointBytes + 8 + 24 + 3; }

void Overwrite(std::string& bytes, std::size_t offset, double value) {
  ASSERT_LE(offset + sizeof value, bytes.size());
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

class ColmapModelValues : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arview_colmap_values_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir_ / "database.db").c_str(), &db), SQLITE_OK);
    fuzz::Exec(db, fuzz::kColmapDatabaseSchema);
    for (int id = 1; id <= 2; ++id) {
      fuzz::Exec(db, "INSERT INTO images VALUES(" + std::to_string(id) + ", 'frames/00000" + std::to_string(id) +
                         ".png');");
      fuzz::Exec(db, "INSERT INTO descriptors VALUES(" + std::to_string(id) + ", 3, 128, randomblob(384));");
    }
    sqlite3_close(db);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The fixture's model with `damage` applied to one of its files, then read.
  map::Map Read(const std::function<void(fuzz::ColmapModelFiles&)>& damage) {
    fuzz::ColmapModelFiles m = fuzz::SmallColmapModel();
    damage(m);
    std::ofstream(dir_ / "cameras.bin", std::ios::binary) << m.cameras;
    std::ofstream(dir_ / "images.bin", std::ios::binary) << m.images;
    std::ofstream(dir_ / "points3D.bin", std::ios::binary) << m.points;
    return ReadColmapMap(dir_, dir_ / "database.db");
  }

  // The error of reading the damaged model (empty when it was read).
  std::string ErrorOf(const std::function<void(fuzz::ColmapModelFiles&)>& damage) {
    try {
      Read(damage);
    } catch (const map::MapError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(ColmapModelValues, TheFixtureModelReads) {
  const map::Map map = Read([](fuzz::ColmapModelFiles&) {});
  EXPECT_EQ(map.keyframes.size(), 2u);
  EXPECT_EQ(map.points.size(), 3u);
  ASSERT_EQ(map.keyframes[1].observations.size(), 3u);
  EXPECT_FLOAT_EQ(map.keyframes[1].observations[1].pixel.x(), 199.5f);  // COLMAP's 200 in OpenCV's pixels
}

// Issue 41: a NaN pixel in images.bin was reported at the save as "map to save as .../map.arvmap:
// keyframe 13 has an observation with an index out of range".
TEST_F(ColmapModelValues, ANonFinitePixelIsRefusedNamingImagesBinTheImageAndTheValue) {
  for (const double bad : {kNaN, kInf, -kInf}) {
    for (const std::size_t y : {0u, 8u}) {
      const std::string error = ErrorOf([&](fuzz::ColmapModelFiles& m) { Overwrite(m.images, ImagePointX(1, 1) + y, bad); });
      SCOPED_TRACE(error);
      EXPECT_EQ(error.rfind((dir_ / "images.bin").string() + ": image 2 ('frames/000002.png') has its 2D point 1 at (", 0),
                0u);
      std::ostringstream value;
      value << bad;
      EXPECT_NE(error.find(value.str()), std::string::npos);
      EXPECT_NE(error.find("pixel coordinates must be finite numbers"), std::string::npos);
    }
  }
}

TEST_F(ColmapModelValues, NonFiniteCamerasPosesAndPointsAreRefusedNamingTheValue) {
  std::string error = ErrorOf([](fuzz::ColmapModelFiles& m) { Overwrite(m.cameras, CameraParameter(2), kNaN); });
  EXPECT_EQ(error.rfind((dir_ / "cameras.bin").string() + ": camera 1's parameter 2 (of 4, model 1) is nan", 0), 0u)
      << error;
  error = ErrorOf([](fuzz::ColmapModelFiles& m) { Overwrite(m.images, ImageTranslationX(0), kInf); });
  EXPECT_EQ(error.rfind((dir_ / "images.bin").string() + ": image 1 ('frames/000001.png') has the rotation", 0), 0u)
      << error;
  EXPECT_NE(error.find("translation (inf, 0, 0)"), std::string::npos) << error;
  error = ErrorOf([](fuzz::ColmapModelFiles& m) { Overwrite(m.points, PointZ(2), -kInf); });
  EXPECT_EQ(error.rfind((dir_ / "points3D.bin").string() + ": 3D point 3 has the position (0.3, -0.2, -inf)", 0), 0u)
      << error;
  error = ErrorOf([](fuzz::ColmapModelFiles& m) { Overwrite(m.points, PointError(0), kNaN); });
  EXPECT_EQ(error.rfind((dir_ / "points3D.bin").string() + ": 3D point 1 has the position (0.1, -0.2, 4) and the error nan", 0),
            0u)
      << error;
}

}  // namespace
}  // namespace arview::mapping
