#include "app/cli/audio_flags.h"

#include <gtest/gtest.h>

#include <vector>

namespace arview::app {
namespace {

// The message CLI11 gives for `args`, or "" when they parse; `value` gets --audio-out's value.
std::string Parse(std::vector<std::string> args, std::string& value) {
  CLI::App app("test");
  AddAudioOutFlag(&app, value);
  std::reverse(args.begin(), args.end());
  try {
    app.parse(args);
  } catch (const CLI::ParseError& error) {
    return error.what();
  }
  return "";
}

TEST(AudioOutFlag, TakesDefaultNoneOrADeviceAndRefusesWhatIsNoDeviceName) {
  std::string value = "default";
  EXPECT_EQ(Parse({}, value), "");
  EXPECT_EQ(value, "default");
  EXPECT_EQ(Parse({"--audio-out", "none"}, value), "");
  EXPECT_EQ(value, "none");
  EXPECT_EQ(Parse({"--audio-out", "plughw:CARD=USB,DEV=0"}, value), "");
  EXPECT_EQ(value, "plughw:CARD=USB,DEV=0");
  const std::string empty = Parse({"--audio-out", ""}, value);
  EXPECT_NE(empty.find("--audio-out: empty; give default, none or an ALSA device name"), std::string::npos) << empty;
  const std::string spaced = Parse({"--audio-out", "hw:1 0"}, value);
  EXPECT_NE(spaced.find("--audio-out: 'hw:1 0' is not an ALSA device name"), std::string::npos) << spaced;
}

TEST(AudioOutFlag, NoneOpensNothingAndSaysNothing) {
  const audio::OpenedAudioOut out = OpenAudioOutOrSilent("none");
  EXPECT_EQ(out.player, nullptr);
  EXPECT_EQ(out.note, "");
}

}  // namespace
}  // namespace arview::app
