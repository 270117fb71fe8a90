#include "app/cli/numeric_flags.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

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

namespace arview::app {
namespace {

// Issue 41, found by fuzz_flags: CLI11 read "042" as octal, so `--seed 042` ran with seed 34.
// Decimal digits are decimal; CLI11's 0x, 0o and 0b prefixes keep their meaning.
TEST(GuardNumericOptions, LeadingZerosAreDecimalNotOctal) {
  auto parse = [](std::vector<std::string> words, std::uint64_t& seed, int& keys) {
    CLI::App app("test");
    app.add_option("--seed", seed);
    app.add_option("--keys", keys)->check(CLI::Range(2, 64));
    GuardNumericOptions(app);
    std::vector<const char*> argv{"test"};
    for (const auto& w : words) argv.push_back(w.c_str());
    app.parse(static_cast<int>(argv.size()), argv.data());
  };
  std::uint64_t seed = 7;
  int keys = 8;
  parse({"--seed", "042", "--keys", "010"}, seed, keys);
  EXPECT_EQ(seed, 42u);
  EXPECT_EQ(keys, 10);
  parse({"--seed", "000", "--keys", "064"}, seed, keys);
  EXPECT_EQ(seed, 0u);
  EXPECT_EQ(keys, 64);
  parse({"--seed=0x10"}, seed, keys);
  EXPECT_EQ(seed, 16u);
  EXPECT_THROW(parse({"--keys", "065"}, seed, keys), CLI::ValidationError);  // 65, not octal 53
  EXPECT_THROW(parse({"--seed", "-042"}, seed, keys), CLI::ValidationError);
}

}  // namespace
}  // namespace arview::app

namespace arview::app {
namespace {

// Issue 57: --fresh-features-after -0.5 meant "never", though only -1 is documented.
TEST(NeverOrNotNegative, TakesMinusOneAndZeroUpAndNothingBetween) {
  const CLI::Validator check = NeverOrNotNegative();
  for (std::string ok : {"-1", "-1.0", "0", "0.25", "30"}) EXPECT_EQ(check(ok), "") << ok;
  for (std::string bad : {"-0.5", "-0.0001", "-2", "-1.5"}) {
    EXPECT_EQ(check(bad), "'" + bad + "' must be -1 (never) or 0 and up") << bad;
  }
}

}  // namespace
}  // namespace arview::app
