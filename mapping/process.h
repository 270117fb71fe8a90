#pragma once
// Running an external program (COLMAP) as a child process: no shell, its standard output and
// error merged, appended to a log file and handed line by line to the caller; stoppable by
// Ctrl-C (SIGINT/SIGTERM) without leaving the child behind.

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace arview::mapping {

struct ProcessError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown when the user interrupted (SIGINT/SIGTERM) a running child; the child was stopped.
struct InterruptedError : ProcessError {
  using ProcessError::ProcessError;
};

struct ProcessResult {
  int exit_code = 0;        // valid when !signaled
  bool signaled = false;    // killed by a signal
  int signal = 0;
  std::vector<std::string> tail;  // the last lines of its output (for error messages)
  bool ok() const { return !signaled && exit_code == 0; }
};

// While alive, SIGINT and SIGTERM set a flag instead of killing this process, so that
// RunProcess can stop its child (the whole child process group) and throw InterruptedError.
// The previous handlers come back on destruction. Not reentrant: one at a time.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  static bool Interrupted();
};

// The full path of `program` found on PATH (or `program` itself if it contains a '/' and is
// executable); empty when not found.
std::string FindExecutable(const std::string& program);

// Runs argv[0] (searched on PATH) with argv in its own process group; every output line is
// appended to `log_path` and passed to `on_line` (may be empty). Returns when the child exits.
// Throws ProcessError when the program cannot be started, InterruptedError when interrupted
// (see InterruptGuard) after stopping the child.
ProcessResult RunProcess(const std::vector<std::string>& argv, const std::filesystem::path& log_path,
                         const std::function<void(const std::string&)>& on_line,
                         std::size_t tail_lines = 30);

}  // namespace arview::mapping
