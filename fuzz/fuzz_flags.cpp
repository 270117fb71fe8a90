// Values given on the command line: the frame spec (--frames), the viewpoint (--viewpoint),
// and numeric flags through CLI11 with app/cli/numeric_flags.h's guard (as main() installs it).
// The input's first byte picks the parser; the rest is the text.
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "anim_authoring/scene.h"
#include "app/cli/numeric_flags.h"
#include "recordings/recording.h"

namespace {

void ParseNumericFlags(const std::string& text) {
  CLI::App app("fuzz");
  double ratio = 0.8;
  float scale = 1;
  std::uint64_t seed = 0;
  int count = 0;
  std::vector<double> pose;
  app.add_option("--ratio", ratio)->check(CLI::Range(0.0, 1.0));
  app.add_option("--scale", scale);
  app.add_option("--seed", seed);
  app.add_option("--count", count);
  app.add_option("--pose", pose)->expected(7);
  arview::app::GuardNumericOptions(app);
  // Words separated by spaces become argv.
  std::vector<std::string> words;
  std::string word;
  for (char c : text) {
    if (c == ' ') {
      words.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  words.push_back(word);
  std::vector<const char*> argv{"fuzz"};
  for (const auto& w : words) argv.push_back(w.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 3) {
      case 0:
        (void)arview::recordings::ParseFrameSpec(text, 1 + data[0] / 3 * 40);
        break;
      case 1:
        (void)arview::authoring::ParseViewpoint(text, "--viewpoint");
        break;
      default:
        ParseNumericFlags(text);
        break;
    }
  } catch (const std::exception&) {
  }
  return 0;
}
