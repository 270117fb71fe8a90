#pragma once
// Runs the arview binary in the background (for tests that signal it while it works): its
// stdout and stderr go to files, the test waits for a condition, signals it and times its exit.
// Also: whether any process still mentions a folder on its command line (a COLMAP child left
// behind).

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/run_command.h"

namespace arview::testing {

class SpawnedArview {
 public:
  SpawnedArview(const std::vector<std::string>& args, const std::filesystem::path& log_stem)
      : out_(log_stem.string() + ".out"), err_(log_stem.string() + ".err") {
    const char* bin = std::getenv("ARVIEW_BIN");
    std::vector<std::string> argv{bin ? bin : "arview"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ == 0) {
      if (!std::freopen("/dev/null", "r", stdin) || !std::freopen(out_.c_str(), "w", stdout) ||
          !std::freopen(err_.c_str(), "w", stderr)) {
        ::_exit(126);
      }
      ::execv(cargv[0], cargv.data());
      ::_exit(127);
    }
  }
  ~SpawnedArview() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }
  SpawnedArview(const SpawnedArview&) = delete;
  SpawnedArview& operator=(const SpawnedArview&) = delete;

  pid_t pid() const { return pid_; }
  std::string Stdout() const { return ReadWholeFile(out_); }
  std::string Stderr() const { return ReadWholeFile(err_); }

  // Polls `condition` every 20 ms until it holds (true) or the process exited / `timeout`
  // passed (false).
  bool WaitFor(const std::function<bool()>& condition, std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (condition()) return true;
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  // Sends `signal_number`, remembers how much stderr held at that moment, and waits up to
  // `timeout` for the exit; the seconds it took (or a negative value when it did not exit).
  double SignalAndTimeExit(int signal_number, std::chrono::seconds timeout) {
    stderr_at_signal_ = Stderr().size();
    const auto start = std::chrono::steady_clock::now();
    ::kill(pid_, signal_number);
    const auto deadline = start + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }

  // Waits for the exit (any status); false on timeout.
  bool WaitExit(std::chrono::seconds timeout) {
    return WaitFor([] { return false; }, timeout) || exited_;
  }

  bool exited() const { return exited_; }
  // The shell's view: the exit code, or 128 + signal for a death by signal.
  int exit_code() const { return exit_code_; }
  // What the process printed on stderr after the signal.
  std::string StderrAfterSignal() const {
    const std::string all = Stderr();
    return stderr_at_signal_ < all.size() ? all.substr(stderr_at_signal_) : "";
  }

  void RemoveLogs() const {
    std::error_code ec;
    std::filesystem::remove(out_, ec);
    std::filesystem::remove(err_, ec);
  }

 private:
  std::string out_, err_;
  pid_t pid_ = -1;
  bool exited_ = false;
  int exit_code_ = -1;
  size_t stderr_at_signal_ = 0;
};

// The live processes (zombies have no command line) other than this one whose command line
// mentions `needle`, as "pid: argv0 argv1 ...".
inline std::vector<std::string> ProcessesMentioning(const std::string& needle) {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::stoi(name) == ::getpid()) continue;
    std::string cmdline = ReadWholeFile(entry.path().string() + "/cmdline");
    for (char& c : cmdline) {
      if (c == '\0') c = ' ';
    }
    if (cmdline.find(needle) != std::string::npos) found.push_back(name + ": " + cmdline);
  }
  return found;
}

}  // namespace arview::testing
