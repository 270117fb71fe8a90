#pragma once
// Where arview keeps what it can compute again but would rather not (the PRT transfer of a
// character, the descriptor index of a map): $ARVIEW_CACHE_DIR/<kind>, else
// $XDG_CACHE_HOME/arview/<kind>, else ~/.cache/arview/<kind>; empty when none of them is set
// (then nothing is cached).

#include <cstdlib>
#include <filesystem>
#include <string>

namespace arview {

inline std::filesystem::path CacheFolder(const std::string& kind) {
  auto set = [](const char* name) -> const char* {
    const char* value = std::getenv(name);
    return value && *value ? value : nullptr;
  };
  if (const char* dir = set("ARVIEW_CACHE_DIR")) return std::filesystem::path(dir) / kind;
  if (const char* dir = set("XDG_CACHE_HOME")) return std::filesystem::path(dir) / "arview" / kind;
  if (const char* dir = set("HOME")) return std::filesystem::path(dir) / ".cache" / "arview" / kind;
  return {};
}

}  // namespace arview
