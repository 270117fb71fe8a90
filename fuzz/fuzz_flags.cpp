// Values given on the command line: the frame spec (--frames), the viewpoint (--viewpoint),
// and numeric flags through CLI11 with app/cli/numeric_flags.h's guard (as main() installs it).
// The input's first byte picks the parser; the rest is the text.
//
// What is accepted is checked, not only that nothing crashes (issue 41: `--seed ''` ran as seed
// 0 and `--frames '1,'` as frame 1, both silently): an accepted frame spec must give exactly the
// frames of a strict reading of the grammar in docs/architecture.md ("0-46:2", "1,5,9-12"; spaces
// only around an item); an accepted viewpoint is a unit vector; an accepted seed is a non-blank,
// non-negative number (its value the number when it is written in decimal digits), an accepted
// floating-point value is finite and within 1e12 (and within its range check). A violation
// aborts: a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "anim_authoring/scene.h"
#include "app/cli/numeric_flags.h"
#include "base/error.h"
#include "recordings/recording.h"

namespace {

[[noreturn]] void Finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_flags: %s\n", what.c_str());
  std::abort();
}

// The frames a spec names by a strict reading of its grammar, or nothing when it is not one:
// items separated by commas, each "N", "A-B" or "A-B:S" (decimal, at most 9 digits, S > 0, A <= B,
// B < frame_count) with spaces or tabs only around it; at least one item.
std::optional<std::set<int>> ReferenceFrames(std::string_view spec, int frame_count) {
  std::set<int> frames;
  auto number = [](std::string_view digits) -> std::optional<int> {
    if (digits.empty() || digits.size() > 9) return std::nullopt;
    int value = 0;
    for (const char c : digits) {
      if (c < '0' || c > '9') return std::nullopt;
      value = 10 * value + (c - '0');
    }
    return value;
  };
  while (true) {
    const size_t comma = spec.find(',');
    std::string_view item = spec.substr(0, comma);
    const size_t first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    if (first == std::string_view::npos) return std::nullopt;  // an empty item
    item = item.substr(first, last + 1 - first);
    const size_t dash = item.find('-'), colon = item.find(':');
    std::optional<int> a, b, step = 1;
    if (dash == std::string_view::npos) {
      if (colon != std::string_view::npos) return std::nullopt;
      a = b = number(item);
    } else {
      a = number(item.substr(0, dash));
      b = number(item.substr(dash + 1, colon == std::string_view::npos ? std::string_view::npos : colon - dash - 1));
      if (colon != std::string_view::npos) {
        if (colon < dash) return std::nullopt;
        step = number(item.substr(colon + 1));
      }
    }
    if (!a || !b || !step || *step <= 0 || *b < *a || *b >= frame_count) return std::nullopt;
    for (long i = *a; i <= *b; i += *step) frames.insert(static_cast<int>(i));
    if (comma == std::string_view::npos) return frames;
    spec.remove_prefix(comma + 1);
  }
}

void CheckFrameSpec(const std::string& spec, int frame_count) {
  std::optional<std::vector<int>> parsed;
  try {
    parsed = arview::recordings::ParseFrameSpec(spec, frame_count);
  } catch (const arview::Error&) {
  }
  const std::optional<std::set<int>> reference = ReferenceFrames(spec, frame_count);
  if (parsed.has_value() != reference.has_value()) {
    Finding("frame spec '" + spec + "' was " + (parsed ? "accepted" : "refused") + ", the grammar " +
            (reference ? "accepts" : "refuses") + " it");
  }
  if (parsed && std::set<int>(parsed->begin(), parsed->end()) != *reference) {
    Finding("frame spec '" + spec + "' gave other frames than the grammar's");
  }
}

void CheckViewpoint(const std::string& text) {
  try {
    const Eigen::Vector3d v = arview::authoring::ParseViewpoint(text, "--viewpoint");
    if (!v.allFinite() || std::abs(v.norm() - 1) > 1e-9) Finding("viewpoint '" + text + "' is not a unit vector");
  } catch (const arview::Error&) {
  }
}

// The value given to `flag` ("--flag v" or "--flag=v") when it is given once, else nothing.
// CLI11 takes "--flag=" with nothing after the '=' as "--flag": its value is the next word.
std::optional<std::string> ValueOf(const std::vector<std::string>& words, const std::string& flag) {
  std::optional<std::string> value;
  int times = 0;
  for (size_t i = 0; i < words.size(); ++i) {
    if ((words[i] == flag || words[i] == flag + "=") && i + 1 < words.size()) {
      value = words[i + 1];
      ++times;
    } else if (words[i].rfind(flag + "=", 0) == 0) {
      value = words[i].substr(flag.size() + 1);
      ++times;
    }
  }
  return times == 1 ? value : std::nullopt;
}

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
    return;
  }
  // Accepted: what was given must be what the flags promise.
  if (const auto given = ValueOf(words, "--seed")) {
    const size_t first = given->find_first_not_of(" \t");
    if (first == std::string::npos || (*given)[first] == '-') Finding("--seed '" + *given + "' was accepted");
    if (given->find_first_not_of("0123456789") == std::string::npos && given->size() <= 19 &&
        seed != std::stoull(*given)) {
      Finding("--seed '" + *given + "' gave " + std::to_string(seed));
    }
  }
  for (const char* flag : {"--ratio", "--scale", "--count"}) {
    if (const auto given = ValueOf(words, flag); given && given->find_first_not_of(" \t") == std::string::npos) {
      Finding(std::string(flag) + " '" + *given + "' (blank) was accepted");
    }
  }
  if (!(ratio >= 0 && ratio <= 1)) Finding("--ratio " + std::to_string(ratio) + " was accepted");
  if (!std::isfinite(scale) || std::abs(scale) > 1e12) Finding("--scale " + std::to_string(scale) + " was accepted");
  for (const double x : pose) {
    if (!std::isfinite(x) || std::abs(x) > 1e12) Finding("--pose holding " + std::to_string(x) + " was accepted");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0:
      CheckFrameSpec(text, 1 + data[0] / 3 * 40);
      break;
    case 1:
      CheckViewpoint(text);
      break;
    default:
      ParseNumericFlags(text);
      break;
  }
  return 0;
}
