#pragma once
// Where tests find real data: ../shared/data beside the project (never copied into it),
// and files from Debian packages (assimp-testmodels, opencv-doc).
//
// On a user's fresh machine a missing folder makes the test skip with a message naming it;
// under ARVIEW_REQUIRE_DATA=1 (set by .ci/run) a missing folder is a failure.

#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace arview::testing {

inline std::filesystem::path SourceDir() {
  if (const char* env = std::getenv("ARVIEW_SOURCE_DIR"); env && *env) return env;
#ifdef ARVIEW_SOURCE_DIR_DEFAULT
  return ARVIEW_SOURCE_DIR_DEFAULT;
#else
  return std::filesystem::current_path();
#endif
}

// ../shared/data/<relative> seen from the project root, or <ARVIEW_DATA_DIR>/<relative> when that
// is set (a checkout that is not beside shared/, e.g. a git worktree).
inline std::filesystem::path SharedData(const std::string& relative) {
  if (const char* env = std::getenv("ARVIEW_DATA_DIR"); env && *env) {
    return (std::filesystem::path(env) / relative).lexically_normal();
  }
  return (SourceDir() / ".." / "shared" / "data" / relative).lexically_normal();
}

inline bool DataRequired() {
  const char* env = std::getenv("ARVIEW_REQUIRE_DATA");
  return env && std::string(env) == "1";
}

// A folder of the test process's own, <temp>/<prefix>_<pid>, made on construction and removed
// with what it holds on destruction: a function-local static one is removed when the process
// exits, whether its tests passed or failed (a failed ASSERT skips the cleanup written after it,
// and /tmp kept hundreds of such folders).
class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& prefix)
      : path_(std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace arview::testing

// Skips (or, under ARVIEW_REQUIRE_DATA=1, fails) the current test when `path` is missing.
// `what` says where the data comes from, e.g. "../shared/data" or "Debian package opencv-doc".
#define ARVIEW_REQUIRE_DATA_PATH(required_path, what)                                              \
  do {                                                                                    \
    const std::filesystem::path arview_required_path_ = (required_path);                           \
    if (!std::filesystem::exists(arview_required_path_)) {                                \
      if (::arview::testing::DataRequired()) {                                            \
        FAIL() << "missing test data " << arview_required_path_ << " (from " << (what)    \
               << "); ARVIEW_REQUIRE_DATA=1 makes this a failure";                        \
      } else {                                                                            \
        GTEST_SKIP() << "needs " << arview_required_path_ << " (from " << (what) << ")";  \
      }                                                                                   \
    }                                                                                     \
  } while (0)
