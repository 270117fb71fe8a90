#include "app/cli/numeric_flags.h"

#include <gtest/gtest.h>

namespace arview::app {
namespace {

TEST(FrameSize, ParsesWidthByHeight) {
  EXPECT_EQ(ParseFrameSize("1920x1080"), cv::Size(1920, 1080));
  EXPECT_EQ(ParseFrameSize("640X480"), cv::Size(640, 480));
}

TEST(FrameSize, RefusesAnythingButTwoRunsOfDigits) {
  for (const char* text : {"", "x", "640x", "x480", "640x480x", "640x480 ", " 640x480", "+640x480", "-640x480",
                           "640x-480", "640*480", "6.4x480", "123456x480", "640x480x2"}) {
    EXPECT_EQ(ParseFrameSize(text), std::nullopt) << "'" << text << "'";
  }
}

TEST(FrameSize, CheckKeepsBothDimensionsInTheirRange) {
  const CLI::Validator check = FrameSizeCheck({160, 120}, {3840, 2160});
  for (std::string ok : {"160x120", "1280x720", "3840x2160"}) EXPECT_EQ(check(ok), "") << ok;
  for (std::string bad : {"159x120", "160x119", "3841x2160", "3840x2161", "00000x0", "1280x720x"}) {
    const std::string message = check(bad);
    EXPECT_NE(message.find("between 160x120 and 3840x2160"), std::string::npos) << bad << ": " << message;
    EXPECT_NE(message.find(bad), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace arview::app
