#pragma once
// A real X session for tests of windows: a virtual X server (Xvfb, on a display number it picks
// itself), child processes stopped when they go out of scope, and shell commands (xdotool,
// ffmpeg's x11grab for screenshots) run against the display. Xvfb, xdotool and ffmpeg come
// from scripts/install-deps.sh.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/run_command.h"
#include "tests/support/test_data.h"

namespace arview::testing {

inline bool OnPath(const std::string& program) {
  return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

#define REQUIRE_PROGRAM(program)                                                             \
  do {                                                                                       \
    if (!::arview::testing::OnPath(program)) {                                               \
      if (::arview::testing::DataRequired()) FAIL() << program << " is missing (scripts/install-deps.sh)"; \
      GTEST_SKIP() << "needs " << program << " (scripts/install-deps.sh installs it)";        \
    }                                                                                        \
  } while (0)

// A process started with fork/exec, stopped (SIGTERM, then SIGKILL) when it goes out of scope.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& stdout_file = "/dev/null", int keep_fd = -1) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int out = ::open(stdout_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, 1);
      const int null = ::open("/dev/null", O_RDONLY);
      ::dup2(null, 0);
      for (int fd = 3; fd < 256; ++fd) {
        if (fd != keep_fd && fd != out) ::close(fd);
      }
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execvp(args[0], args.data());
      ::_exit(127);
    }
  }
  ~Child() {
    if (pid_ <= 0 || exited_) return;
    ::kill(pid_, SIGTERM);
    if (Wait(5) < 0) {
      ::kill(pid_, SIGKILL);
      Wait(5);
    }
  }
  // The exit status, or -1 if it is still running after `seconds`.
  int Wait(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < until) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
};

// Xvfb on a display number it picks itself (-displayfd), 1280x720 24-bit. -noreset: by default
// the server resets when its last client leaves (the check that it answers, an xdotool call), and
// a client connecting meanwhile was refused ("cannot open display").
class VirtualDisplay {
 public:
  VirtualDisplay() {
    int fds[2];
    if (::pipe(fds) != 0) return;
    server_ = std::make_unique<Child>(std::vector<std::string>{"Xvfb", "-displayfd", std::to_string(fds[1]), "-screen", "0",
                                                               "1280x720x24", "-nolisten", "tcp", "-noreset"},
                                      "/dev/null", fds[1]);
    ::close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    while (::poll(&p, 1, 20000) > 0) {
      char c;
      if (::read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    ::close(fds[0]);
    if (!number.empty()) name_ = ":" + number;
  }
  const std::string& name() const { return name_; }

 private:
  std::unique_ptr<Child> server_;
  std::string name_;
};

inline std::string Shell(const std::string& command, const std::string& display) {
  const std::string out = "/tmp/arview_view_shell_" + std::to_string(::getpid());
  const int rc = std::system(("DISPLAY=" + display + " " + command + " >" + out + " 2>&1").c_str());
  std::string text = ReadWholeFile(out);
  std::remove(out.c_str());
  EXPECT_EQ(rc, 0) << command << ": " << text;
  return text;
}

// A test in an X session: its own folder (kept when the test fails) and a virtual display,
// once the programs it needs are there. Base: ::testing::Test or ::testing::TestWithParam<P>.
template <class Base>
class XSessionTest : public Base {
 protected:
  // Call first in SetUp, then check HasFatalFailure() / IsSkipped().
  void StartXSession(const std::string& name) {
    REQUIRE_PROGRAM("Xvfb");
    REQUIRE_PROGRAM("xdotool");
    REQUIRE_PROGRAM("ffmpeg");
    dir_ = std::filesystem::temp_directory_path() / ("arview_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    // A server that reported its display but does not answer (seen once under a parallel
    // ctest: "cannot open display ':0'") is replaced once by a fresh one.
    for (int attempt = 0; attempt < 2; ++attempt) {
      display_ = std::make_unique<VirtualDisplay>();
      if (!display_->name().empty() && Answers(display_->name())) return;
      std::fprintf(stderr, "[x session] Xvfb on '%s' does not answer; starting another\n", display_->name().c_str());
    }
    FAIL() << "Xvfb did not start, or does not answer on " << display_->name();
  }
  static bool Answers(const std::string& display) {
    return std::system(("DISPLAY=" + display + " xdotool getdisplaygeometry >/dev/null 2>&1").c_str()) == 0;
  }
  // The id of arview's window once its title shows the live status (frames have been shown), or
  // "" when `app` ended first or none came within 60 s.
  std::string WaitForLiveWindow(Child& app) {
    const std::string d = display_->name();
    for (int i = 0; i < 600 && app.Wait(0) < 0; ++i) {
      const int rc = std::system(("DISPLAY=" + d + " xdotool search --name '^arview .*fps' > " +
                                  ShellQuote((dir_ / "window_id").string()) + " 2>/dev/null").c_str());
      if (rc == 0) {
        std::string id = ReadWholeFile((dir_ / "window_id").string());
        id = id.substr(0, id.find('\n'));
        if (!id.empty()) return id;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return "";
  }
  void TearDown() override {
    display_.reset();
    if (!this->HasFailure() && !dir_.empty()) std::filesystem::remove_all(dir_);
  }

  std::filesystem::path dir_;
  std::unique_ptr<VirtualDisplay> display_;
};

}  // namespace arview::testing
