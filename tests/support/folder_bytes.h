#pragma once
// Every regular file under a folder with its bytes: a test's before and after, so that "nothing
// changed on disk" is checked file by file.

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace arview::testing {

inline std::map<std::string, std::string> FolderBytes(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    files[std::filesystem::relative(e.path(), dir).string()] = bytes.str();
  }
  return files;
}

}  // namespace arview::testing
