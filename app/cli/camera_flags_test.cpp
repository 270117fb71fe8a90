#include "app/cli/camera_flags.h"

#include <gtest/gtest.h>

namespace arview::app {
namespace {

std::string Check(const CLI::Validator& v, std::string text) { return v(text); }

TEST(CameraFlags, FocusTakesItsWordsOrAWholeNumber) {
  for (const char* ok : {"lock", "auto", "keep", "0", "120", "-5"}) EXPECT_EQ(Check(FocusCheck(), ok), "") << ok;
  for (const char* bad : {"", "near", "12.5", "1e3", "120 "}) {
    EXPECT_NE(Check(FocusCheck(), bad).find("is not lock, auto, keep or a whole number"), std::string::npos) << bad;
  }
}

TEST(CameraFlags, ExposureTakesItsWordsOrAWholeNumber) {
  for (const char* ok : {"auto", "lock", "250"}) EXPECT_EQ(Check(ExposureCheck(), ok), "") << ok;
  for (const char* bad : {"keep", "fast", "", "3ms"}) EXPECT_NE(Check(ExposureCheck(), bad), "") << bad;
}

TEST(CameraFlags, ParsedFlagsFillTheCameraOptions) {
  CLI::App app;
  CameraFlags flags;
  AddCameraFlags(&app, flags, "default 640x480");
  app.parse("--format mjpeg --fps 15 --focus 90 --exposure lock", false);
  recordings::V4l2Options options;
  ApplyCameraFlags(flags, options);
  EXPECT_EQ(options.fps, 15);
  EXPECT_EQ(options.format, "mjpeg");
  EXPECT_EQ(options.focus, "90");
  EXPECT_EQ(options.exposure, "lock");
  EXPECT_THROW(app.parse("--focus near", false), CLI::ValidationError);
}

}  // namespace
}  // namespace arview::app
