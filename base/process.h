#pragma once
// Running an external program (COLMAP) as a child process: no shell, its standard output and
// error merged, appended to a log file and handed line by line to the caller.
//
// The child lives and dies with the run:
// - it gets its own process group, so the terminal's Ctrl-C reaches only arview, and
//   stopping the run stops the whole group (SIGTERM, then SIGKILL after a grace period);
// - a cancelled token (base/cancellation.h) stops it and throws CancelledError;
// - prctl(PR_SET_PDEATHSIG, SIGKILL) kills it when arview dies any other way (SIGKILL, a
//   crash). Linux ties this to the *thread* that started the child, so RunProcess must be
//   called from a thread that outlives the child (it does: it waits for it).

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "base/cancellation.h"
#include "base/error.h"

namespace arview {

class ProcessError : public Error {
 public:
  using Error::Error;
};

struct ProcessResult {
  int exit_code = 0;        // valid when !signaled
  bool signaled = false;    // killed by a signal
  int signal = 0;
  std::vector<std::string> tail;  // the last lines of its output (for error messages)
  bool ok() const { return !signaled && exit_code == 0; }
};

struct ProcessOptions {
  std::size_t tail_lines = 30;
  // After SIGTERM to the group, how long the child gets before SIGKILL. Short: an
  // interrupted run must end within about two seconds.
  std::chrono::milliseconds stop_grace{800};
};

// The full path of `program` found on PATH (or `program` itself if it contains a '/' and is
// executable); empty when not found.
std::string FindExecutable(const std::string& program);

// Runs argv[0] (searched on PATH) with argv; every output line is appended to `log_path` and
// passed to `on_line` (may be empty). Returns when the child exits. Throws ProcessError when
// the program cannot be started, CancelledError (after stopping the child's group) when
// `cancel` is cancelled; an exception from `on_line` also stops the child, then propagates.
ProcessResult RunProcess(const std::vector<std::string>& argv, const std::filesystem::path& log_path,
                         const std::function<void(const std::string&)>& on_line,
                         const CancellationToken& cancel = {}, const ProcessOptions& options = {});

}  // namespace arview
