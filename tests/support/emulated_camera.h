#pragma once
// Runs the arview binary with the emulated camera (tests/support/fake_v4l2_device.cpp,
// /dev/video-arview-fake) preloaded, its environment variables set, and optionally paused or
// interrupted as a user would. ARVIEW_FAKE_V4L2_LIBRARY is defined by tests/CMakeLists.txt.

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/run_command.h"
#include "tests/support/sanitizer_slowdown.h"

namespace arview::testing {

inline constexpr const char* kEmulatedCamera = "/dev/video-arview-fake";

// `env`: the emulated camera's settings (ARVIEW_FAKE_CAMERA_*). `pause` (seconds after the
// start, for how long): the process is stopped in between (SIGSTOP), as a reader that falls
// behind the camera. With `pause_after_file`, the seconds count from when that file appears
// (e.g. a recording's fifth frame: the camera streams, however long the start-up took under a
// sanitizer; 60 s at most). `interrupt_after` > 0: Ctrl-C (SIGINT) after that many seconds, as a user
// ends `run`; with `interrupt_after_text`, the seconds count from when the command's stderr first
// holds that text (the first localized view's line: the session reached its point however slowly
// a loaded machine started it; 60 s at most). Its stdout, stderr and exit status go through
// files in `dir`.
inline CommandResult RunWithEmulatedCamera(const std::vector<std::string>& args,
                                           const std::map<std::string, std::string>& env,
                                           const std::filesystem::path& dir, std::pair<double, double> pause = {0, 0},
                                           double interrupt_after = 0,
                                           const std::filesystem::path& pause_after_file = {},
                                           const std::string& interrupt_after_text = {}) {
  const char* bin = std::getenv("ARVIEW_BIN");
  std::string cmd = "LD_PRELOAD=" + ShellQuote(ARVIEW_FAKE_V4L2_LIBRARY) +
                    " ASAN_OPTIONS=\"$ASAN_OPTIONS:verify_asan_link_order=0\"";
  for (const auto& [name, value] : env) cmd += " " + name + "=" + ShellQuote(value);
  // --preserve-status: the exit status is arview's, not timeout's 124. --foreground: the signal
  // goes to arview alone; without it timeout signals its whole process group too, and arview,
  // getting SIGINT twice, takes the second for a user's second Ctrl-C and dies at once.
  const bool interrupt_counts_from_text = interrupt_after > 0 && !interrupt_after_text.empty();
  if (interrupt_after > 0 && !interrupt_counts_from_text)
    cmd += " timeout --foreground --preserve-status -s INT " + std::to_string(interrupt_after);
  cmd += " " + ShellQuote(bin ? bin : "arview");
  for (const std::string& a : args) cmd += " " + ShellQuote(a);
  const std::filesystem::path out = dir / "cmd.out", err = dir / "cmd.err", code = dir / "cmd.code";
  cmd += " >" + ShellQuote(out.string()) + " 2>" + ShellQuote(err.string()) + " </dev/null";
  if (interrupt_counts_from_text) {
    // SIGINT to arview alone (its pid: the job is the one simple command), as timeout --foreground.
    cmd = "{ " + cmd + " & pid=$!; for i in $(seq 600); do grep -qF -- " + ShellQuote(interrupt_after_text) + " " +
          ShellQuote(err.string()) + " && break; kill -0 $pid 2>/dev/null || break; sleep 0.1; done; sleep " +
          std::to_string(interrupt_after) + "; kill -INT $pid 2>/dev/null; wait $pid; echo $? >" + ShellQuote(code.string()) + "; }";
  } else if (pause.second > 0) {
    const std::string wait_for_file =
        pause_after_file.empty()
            ? ""
            : "for i in $(seq 600); do [ -e " + ShellQuote(pause_after_file.string()) + " ] && break; sleep 0.1; done; ";
    cmd = "{ " + cmd + " & pid=$!; " + wait_for_file + "sleep " + std::to_string(pause.first) + "; kill -STOP $pid; sleep " +
          std::to_string(pause.second) + "; kill -CONT $pid; wait $pid; echo $? >" + ShellQuote(code.string()) + "; }";
  } else {
    cmd = "{ " + cmd + "; echo $? >" + ShellQuote(code.string()) + "; }";
  }
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  CommandResult r;
  r.exit_code = std::stoi(ReadWholeFile(code.string()));
  r.out = ReadWholeFile(out.string());
  r.err = ReadWholeFile(err.string());
  return r;
}

}  // namespace arview::testing
