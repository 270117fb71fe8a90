#include "app/cli/output_flags.h"

#include <filesystem>

#include "app/cli/commands.h"

namespace arview::app {

namespace fs = std::filesystem;

namespace {

// "" when `text` can name a file to write, else why not.
std::string WhyNotAnOutputFile(const std::string& text) {
  if (text.empty()) return "an empty name: give the file to write";
  if (text.back() == '/') return "'" + text + "' names a folder (it ends in '/'): give the file to write";
  const fs::path path(text);
  std::error_code ec;
  if (fs::is_directory(path, ec)) return "'" + text + "' is a folder: give the file to write";
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, ec)) return "'" + text + "': the folder " + folder.string() + " does not exist";
  return "";
}

// One file for two names: the same path, or two paths to one existing file (a link, "./").
bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec, ec_a, ec_b;
  if (fs::equivalent(a, b, ec)) return true;
  // Absolute first: weakly_canonical leaves a relative path whose folder does not exist yet as it is.
  const fs::path canonical_a = fs::weakly_canonical(fs::absolute(a), ec_a);
  const fs::path canonical_b = fs::weakly_canonical(fs::absolute(b), ec_b);
  return !ec_a && !ec_b && canonical_a == canonical_b;
}

}  // namespace

CLI::Validator OutputFileCheck() {
  return CLI::Validator(WhyNotAnOutputFile, "");  // "": --help's type column as it was
}

void RequireDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (std::size_t j = i + 1; j < outputs.size(); ++j) {
      const auto& [flag_a, a] = outputs[i];
      const auto& [flag_b, b] = outputs[j];
      if (!a.empty() && !b.empty() && SameFile(a, b)) {
        throw CommandError(flag_a + " " + a + " and " + flag_b + " " + b +
                               " name one file: each output needs its own (the one written last would replace the other)",
                           2);
      }
    }
  }
}

}  // namespace arview::app
