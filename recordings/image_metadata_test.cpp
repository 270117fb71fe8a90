#include "recordings/image_metadata.h"

#include <cmath>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <libexif/exif-data.h>
#include <opencv2/imgcodecs.hpp>

#include "recordings/importers.h"
#include "recordings/recording.h"
#include "recordings/test_helpers.h"

namespace arview::recordings {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::WriteImage;

// A JPEG of `width` x `height` with an EXIF block (APP1) holding a 35 mm-equivalent focal length.
void WriteJpegWithFocal35(const fs::path& file, int width, int height, int focal_35mm) {
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", cv::Mat(height, width, CV_8UC3, cv::Scalar(90, 120, 150)), jpeg);
  ExifData* exif = exif_data_new();
  exif_data_set_byte_order(exif, EXIF_BYTE_ORDER_INTEL);
  ExifEntry* entry = exif_entry_new();
  exif_content_add_entry(exif->ifd[EXIF_IFD_EXIF], entry);
  exif_entry_initialize(entry, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
  exif_set_short(entry->data, EXIF_BYTE_ORDER_INTEL, static_cast<ExifShort>(focal_35mm));
  exif_entry_unref(entry);
  unsigned char* block = nullptr;
  unsigned int size = 0;
  exif_data_save_data(exif, &block, &size);
  exif_data_unref(exif);
  ASSERT_NE(block, nullptr);
  const unsigned int segment = size + 2;
  std::vector<unsigned char> out(jpeg.begin(), jpeg.begin() + 2);  // SOI
  out.insert(out.end(), {0xFF, 0xE1, static_cast<unsigned char>(segment >> 8), static_cast<unsigned char>(segment & 0xFF)});
  out.insert(out.end(), block, block + size);
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  free(block);
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
}

TEST(ReadFocalFromExif, TakesThe35mmEquivalentOnTheDiagonal) {
  TempDir dir("exif");
  WriteJpegWithFocal35(dir.path() / "a.jpg", 64, 48, 26);
  std::string ignored;
  const auto focal = ReadFocalFromExif(dir.path() / "a.jpg", 64, 48, &ignored);
  ASSERT_TRUE(focal);
  EXPECT_NEAR(focal->focal_px, 26.0 / 43.2666 * 80.0, 1e-3);  // the 64x48 image's diagonal is 80 px
  EXPECT_NE(focal->description.find("26 mm"), std::string::npos) << focal->description;
  EXPECT_TRUE(ignored.empty());
}

TEST(ReadFocalFromExif, NoExifOrNonsenseGivesNothingAndSaysWhatWasIgnored) {
  TempDir dir("exif_bad");
  WriteImage(dir.path() / "plain.jpg", 64, 48, 1);
  std::string ignored;
  EXPECT_FALSE(ReadFocalFromExif(dir.path() / "plain.jpg", 64, 48, &ignored));
  EXPECT_TRUE(ignored.empty());
  WriteJpegWithFocal35(dir.path() / "odd.jpg", 64, 48, 1);  // a 1 mm lens on a full frame: nonsense
  EXPECT_FALSE(ReadFocalFromExif(dir.path() / "odd.jpg", 64, 48, &ignored));
  EXPECT_NE(ignored.find("odd.jpg"), std::string::npos) << ignored;
  EXPECT_NE(ignored.find("ignored"), std::string::npos) << ignored;
}

TEST(ImportWithoutCamera, GuessesTheFocalMarksTheCameraUncalibratedAndSaysSo) {
  TempDir dir("import_guess");
  for (int i = 0; i < 3; ++i) WriteImage(dir.path() / ("src/" + std::to_string(i) + ".png"), 64, 48, i);
  const ImportResult result = ImportImages(dir.path() / "src", dir.path() / "out");
  EXPECT_EQ(result.frame_count, 3);
  ASSERT_FALSE(result.notes.empty());
  EXPECT_NE(result.notes.back().find("not calibrated"), std::string::npos) << result.notes.back();
  const Recording rec = LoadRecording(dir.path() / "out");
  EXPECT_FALSE(rec.camera.calibrated);
  EXPECT_DOUBLE_EQ(rec.camera.fx, 0.6 * 80);  // the 64x48 image's diagonal is 80 px
  EXPECT_DOUBLE_EQ(rec.camera.fy, 0.6 * 80);
  EXPECT_DOUBLE_EQ(rec.camera.cx, 31.5);
  EXPECT_DOUBLE_EQ(rec.camera.cy, 23.5);
  EXPECT_NE(rec.camera.intrinsics_source.find("guess"), std::string::npos) << rec.camera.intrinsics_source;
}

TEST(ImportWithoutCamera, AStatedFieldOfViewOrTheExifFocalWins) {
  TempDir dir("import_fov");
  for (int i = 0; i < 2; ++i) WriteJpegWithFocal35(dir.path() / ("src/" + std::to_string(i) + ".jpg"), 64, 48, 26);
  ImportOptions options;
  ImportImages(dir.path() / "src", dir.path() / "exif", options);
  EXPECT_NEAR(LoadRecording(dir.path() / "exif").camera.fx, 26.0 / 43.2666 * 80.0, 1e-3);
  options.horizontal_fov_deg = 90.0;
  ImportImages(dir.path() / "src", dir.path() / "fov", options);
  const Recording rec = LoadRecording(dir.path() / "fov");
  EXPECT_NEAR(rec.camera.fx, 32.0, 1e-9);  // 90° across 64 px
  EXPECT_FALSE(rec.camera.calibrated);
  options.horizontal_fov_deg = 180.0;
  try {
    ImportImages(dir.path() / "src", dir.path() / "bad", options);
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("--fov"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "bad"));
}

TEST(ImportWithoutCamera, AnImageOfAnotherSizeThanTheFirstIsNamed) {
  TempDir dir("import_sizes");
  WriteImage(dir.path() / "src/a.png", 64, 48, 1);
  WriteImage(dir.path() / "src/b.png", 48, 64, 2);
  try {
    ImportImages(dir.path() / "src", dir.path() / "out");
    FAIL() << "expected a RecordingError";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("b.png"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arview::recordings
