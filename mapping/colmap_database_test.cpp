// COLMAP's database through its one layer (mapping/colmap_database.h): what cannot be opened is
// named, a failed write names the file and the step and leaves nothing half done.

#include "mapping/colmap_database.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "map/map_file.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;
using Access = ColmapDatabase::Access;

class ColmapDatabaseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arview_colmap_database_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A database with COLMAP's cameras and images tables and `cameras` cameras.
  fs::path Make(const std::string& name, int cameras) {
    const fs::path file = dir_ / name;
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    std::string sql =
        "CREATE TABLE cameras(camera_id INTEGER PRIMARY KEY, model INTEGER, width INTEGER, height INTEGER, params BLOB);"
        "CREATE TABLE images(image_id INTEGER PRIMARY KEY, name TEXT, camera_id INTEGER);"
        "INSERT INTO images VALUES(1, 'frames/000001.png', 1), (2, 'frames/000002.png', 1);";
    for (int c = 1; c <= cameras; ++c) sql += "INSERT INTO cameras VALUES(" + std::to_string(c) + ", 2, 640, 480, NULL);";
    EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
    return file;
  }

  static std::string ErrorOf(const std::function<void()>& f) {
    try {
      f();
    } catch (const map::MapError& e) {
      return e.what();
    }
    return "(no error)";
  }

  fs::path dir_;
};

TEST_F(ColmapDatabaseTest, WhatIsNotADatabaseFileIsNamedWithWhatItIs) {
  const fs::path missing = dir_ / "missing.db";
  EXPECT_EQ(ErrorOf([&] { ColmapDatabase(missing, Access::kRead); }), missing.string() + ": COLMAP database missing");
  EXPECT_EQ(ErrorOf([&] { ColmapDatabase(dir_, Access::kReadWrite); }),
            dir_.string() + ": is a directory, not a COLMAP database file");
  const fs::path fifo = dir_ / "fifo.db";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(ErrorOf([&] { ColmapDatabase(fifo, Access::kRead); }), fifo.string() + ": is a FIFO, not a COLMAP database file");
}

TEST_F(ColmapDatabaseTest, ImagesAreReadWithTheirCamera) {
  ColmapDatabase db(Make("database.db", 1), Access::kRead);
  const auto images = db.Images();
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[1].id, 2u);
  EXPECT_EQ(images[1].name, "frames/000002.png");
  EXPECT_EQ(images[1].camera_id, 1);
  EXPECT_EQ(db.ImageId("frames/000001.png"), 1u);
  EXPECT_EQ(db.ImageName(2), "frames/000002.png");
}

TEST_F(ColmapDatabaseTest, AFailedWriteNamesTheStepAndIsRolledBack) {
  const fs::path file = Make("database.db", 1);
  ColmapDatabase db(file, Access::kReadWrite);
  EXPECT_EQ(ErrorOf([&] {
              db.Execute("BEGIN; DELETE FROM images; INSERT INTO no_such_table VALUES(1); COMMIT;", "clear old matches");
            }),
            file.string() + ": cannot clear old matches (SQLite: no such table: no_such_table)");
  EXPECT_EQ(db.Images().size(), 2u);  // the DELETE before the failure was rolled back
  db.Execute("BEGIN; DELETE FROM images WHERE image_id = 2; COMMIT;", "remove an image");  // no transaction left open
  EXPECT_EQ(db.Images().size(), 1u);
}

TEST_F(ColmapDatabaseTest, TheCameraIsSetOnlyWhenThereIsExactlyOne) {
  const fs::path two = Make("two.db", 2);
  EXPECT_EQ(ErrorOf([&] { ColmapDatabase(two, Access::kReadWrite).SetSingleCameraParams({500, 320, 240, 0}); }),
            two.string() + ": cannot set its camera's parameters (2 cameras; one camera expected)");
  ColmapDatabase(Make("one.db", 1), Access::kReadWrite).SetSingleCameraParams({500, 320, 240, 0});
}

TEST_F(ColmapDatabaseTest, APartFailingItsPreconditionIsRefusedWithTheReasonAndDetached) {
  const fs::path file = Make("database.db", 1);
  const fs::path part = Make("part.db", 2);
  ColmapDatabase db(file, Access::kReadWrite);
  const std::string one_camera = "SELECT (SELECT COUNT(*) FROM part.cameras) = 1";
  EXPECT_EQ(ErrorOf([&] {
              db.ExecuteWithPart(part, "INSERT INTO main.images SELECT * FROM part.images;", "add the part's images",
                                 one_camera, "its camera is not the database's one camera");
            }),
            file.string() + ": cannot add the part's images (its camera is not the database's one camera)");
  // Detached again: attaching a part as "part" once more works.
  db.ExecuteWithPart(part, "DELETE FROM main.images WHERE image_id IN (SELECT image_id FROM part.images);",
                     "remove the part's images");
  EXPECT_TRUE(db.Images().empty());
}

TEST_F(ColmapDatabaseTest, ACopyHoldsTheRowsAndAFailedCopyLeavesNoFile) {
  const fs::path file = Make("database.db", 1);
  CopyColmapDatabase(file, dir_ / "copy.db");
  EXPECT_EQ(ColmapDatabase(dir_ / "copy.db", Access::kRead).Images().size(), 2u);
  const fs::path nowhere = dir_ / "no such folder" / "copy.db";
  EXPECT_NE(ErrorOf([&] { CopyColmapDatabase(file, nowhere); }).find(file.string() + ": cannot copy it to " + nowhere.string()),
            std::string::npos);
  EXPECT_FALSE(fs::exists(nowhere));
}

}  // namespace
}  // namespace arview::mapping
