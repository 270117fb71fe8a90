#include "app/numeric_flags.h"

#include <cmath>
#include <cstdlib>
#include <string>

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

void Guard(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    // An empty description keeps --help's type column as it was.
    if (type.rfind("FLOAT", 0) == 0) option->check(CLI::Validator(CheckFinite, ""));
    if (type.rfind("UINT", 0) == 0) option->check(CLI::Validator(CheckNotNegative, ""));
  }
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) Guard(*sub);
}

}  // namespace

void GuardNumericOptions(CLI::App& app) { Guard(app); }

}  // namespace arview::app
