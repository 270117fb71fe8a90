#include "app/cli/numeric_flags.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

namespace arview::app {

namespace {

// CLI11 prints what a validator returns after "--flag: ": the value and the problem.
std::string CheckFinite(std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin) return "";  // not a number at all: CLI11's own conversion says so
  if (!std::isfinite(value)) return "'" + text + "' is not a finite number";
  if (std::abs(value) > 1e12) return "'" + text + "' is too large (at most 1e12 in magnitude)";
  return "";
}

std::string CheckNotNegative(std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first != std::string::npos && text[first] == '-') return "'" + text + "' is negative (must be 0 or more)";
  return "";
}

// CLI11 converts an empty value to 0 (`--seed ''` ran with seed 0).
std::string CheckNotBlank(std::string& text) {
  if (text.find_first_not_of(" \t") == std::string::npos) return "an empty value (a number is needed)";
  return "";
}

// CLI11 reads an integer written with a leading zero as octal: `--seed 042` ran with seed 34
// (found by fuzz_flags). Every flag is documented in decimal, so the zeros are dropped before
// CLI11 converts the text (0x, 0o and 0b prefixes are left to it: they say what they are).
std::string LeadingZerosAsDecimal(std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const size_t digits = first + (text[first] == '-' || text[first] == '+' ? 1 : 0);
  const size_t end = text.find_last_not_of(" \t") + 1;
  if (end <= digits + 1 || text[digits] != '0') return "";
  if (text.find_first_not_of("0123456789", digits) < end) return "";  // not plain decimal digits
  const size_t significant = std::min(text.find_first_not_of('0', digits), end - 1);
  text.erase(digits, significant - digits);
  return "";
}

void Guard(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    // An empty description keeps --help's type column as it was.
    if (type.rfind("FLOAT", 0) == 0) option->check(CLI::Validator(CheckFinite, ""));
    if (type.rfind("UINT", 0) == 0) option->check(CLI::Validator(CheckNotNegative, ""));
    if (type.rfind("UINT", 0) == 0 || type.rfind("INT", 0) == 0) {
      option->transform(CLI::Validator(LeadingZerosAsDecimal, ""));  // first, before any range check
    }
    if (type.rfind("FLOAT", 0) == 0 || type.rfind("UINT", 0) == 0 || type.rfind("INT", 0) == 0)
      option->check(CLI::Validator(CheckNotBlank, ""));
  }
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) Guard(*sub);
}

}  // namespace

void GuardNumericOptions(CLI::App& app) { Guard(app); }

std::optional<cv::Size> ParseFrameSize(const std::string& text) {
  const size_t x = text.find_first_of("xX");
  if (x == std::string::npos) return std::nullopt;
  auto dimension = [](std::string_view digits) -> std::optional<int> {
    if (digits.empty() || digits.size() > 5) return std::nullopt;
    int value = 0;
    for (const char c : digits) {
      if (c < '0' || c > '9') return std::nullopt;
      value = 10 * value + (c - '0');
    }
    return value;
  };
  const std::optional<int> width = dimension(std::string_view(text).substr(0, x));
  const std::optional<int> height = dimension(std::string_view(text).substr(x + 1));
  if (!width || !height) return std::nullopt;
  return cv::Size(*width, *height);
}

CLI::Validator FrameSizeCheck(cv::Size smallest, cv::Size largest) {
  const std::string range = std::to_string(smallest.width) + "x" + std::to_string(smallest.height) + " and " +
                            std::to_string(largest.width) + "x" + std::to_string(largest.height);
  auto check = [smallest, largest, range](std::string& text) -> std::string {
    const std::optional<cv::Size> size = ParseFrameSize(text);
    if (!size || size->width < smallest.width || size->height < smallest.height || size->width > largest.width ||
        size->height > largest.height) {
      return "'" + text + "' must be WIDTHxHEIGHT between " + range + ", e.g. 1280x720";
    }
    return "";
  };
  return CLI::Validator(check, "WIDTHxHEIGHT");
}

CLI::Validator NeverOrNotNegative() {
  const auto check = [](const std::string& text) -> std::string {
    double value = 0;
    if (!CLI::detail::lexical_cast(text, value)) return "";  // not a number: the option's own check says so
    if (value == -1 || value >= 0) return "";
    return "'" + text + "' must be -1 (never) or 0 and up";
  };
  return CLI::Validator(check, "");
}

CLI::Validator BoardSizeCheck() {
  auto check = [](std::string& text) -> std::string {
    const std::optional<cv::Size> size = ParseFrameSize(text);
    if (!size || size->width < 2 || size->height < 2 || size->width > 99 || size->height > 99)
      return "'" + text + "' must be the board's inner corners COLUMNSxROWS, each 2..99, e.g. 9x6";
    return "";
  };
  return CLI::Validator(check, "COLUMNSxROWS");
}

}  // namespace arview::app
