#include "base/process.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

namespace arview {
namespace {

namespace fs = std::filesystem;

fs::path TempPath(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("arview_process_test_" + std::to_string(::getpid()) + "_" + name);
  fs::remove(p);
  return p;
}

// Whether `pid` is a live process (a zombie waiting for its reaper counts as gone).
bool Alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(stat, text)) return false;
  const auto close = text.rfind(')');
  return close != std::string::npos && close + 2 < text.size() && text[close + 2] != 'Z';
}

// Reads the pid a child wrote into `file`, waiting up to 5 s for it to appear.
pid_t ReadPid(const fs::path& file) {
  for (int i = 0; i < 250; ++i) {
    std::ifstream in(file);
    pid_t pid = 0;
    if (in >> pid && pid > 0) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

TEST(RunProcess, PassesEveryLineAndTheExitCode) {
  const fs::path log = TempPath("lines.log");
  std::vector<std::string> seen;
  const ProcessResult r = RunProcess({"sh", "-c", "echo one; echo two 1>&2; printf 'three\\rfour'; exit 3"}, log,
                                     [&](const std::string& line) { seen.push_back(line); });
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.signaled);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(seen, (std::vector<std::string>{"one", "two", "three", "four"}));
  EXPECT_EQ(r.tail, seen);
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("two\n"), std::string::npos);
  EXPECT_NE(text.str().find("(exit 3)"), std::string::npos);
  fs::remove(log);
}

TEST(RunProcess, KeepsOnlyTheTail) {
  const fs::path log = TempPath("tail.log");
  ProcessOptions options;
  options.tail_lines = 2;
  const ProcessResult r = RunProcess({"sh", "-c", "for i in 1 2 3 4 5 6; do echo $i; done"}, log, {}, {}, options);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.tail, (std::vector<std::string>{"5", "6"}));
  fs::remove(log);
}

TEST(RunProcess, MissingProgramIsAClearError) {
  const fs::path log = TempPath("missing.log");
  try {
    RunProcess({"arview-no-such-program-xyz"}, log, {});
    FAIL() << "expected ProcessError";
  } catch (const ProcessError& e) {
    EXPECT_NE(std::string(e.what()).find("arview-no-such-program-xyz"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
  fs::remove(log);
}

TEST(RunProcess, ReportsAChildKilledByASignal) {
  const fs::path log = TempPath("signal.log");
  const ProcessResult r = RunProcess({"sh", "-c", "kill -9 $$"}, log, {});
  EXPECT_TRUE(r.signaled);
  EXPECT_EQ(r.signal, 9);
  fs::remove(log);
}

TEST(RunProcess, ACancelledTokenStopsTheWholeGroupPromptly) {
  const fs::path log = TempPath("cancel.log");
  const fs::path pid_file = TempPath("grandchild.pid");
  CancellationToken token;
  std::thread canceller([token] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    token.Cancel(SIGTERM);
  });
  const auto start = std::chrono::steady_clock::now();
  // The child starts a grandchild in its group that ignores SIGTERM: only SIGKILL to the
  // group ends it.
  try {
    RunProcess({"sh", "-c", "sh -c 'trap \"\" TERM; echo $$ > " + pid_file.string() + "; exec sleep 60' & wait"}, log,
               {}, token);
    ADD_FAILURE() << "expected CancelledError";
  } catch (const CancelledError& e) {
    EXPECT_EQ(e.signal_number(), SIGTERM);
    EXPECT_EQ(e.exit_code(), 143);
    EXPECT_NE(std::string(e.what()).find("interrupted"), std::string::npos);
  }
  canceller.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  const pid_t grandchild = ReadPid(pid_file);
  ASSERT_GT(grandchild, 0);
  for (int i = 0; i < 50 && Alive(grandchild); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(Alive(grandchild)) << "the grandchild outlived the run";
  fs::remove(log);
  fs::remove(pid_file);
}

TEST(RunProcess, SigintUnderTheScopedHandlerCancelsInsteadOfKilling) {
  const fs::path log = TempPath("sigint.log");
  ScopedSignalCancellation signals;
  std::thread interrupter([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::kill(::getpid(), SIGINT);  // as Ctrl-C would: handled by the token, not fatal
  });
  try {
    RunProcess({"sleep", "60"}, log, {}, signals.token());
    ADD_FAILURE() << "expected CancelledError";
  } catch (const CancelledError& e) {
    EXPECT_EQ(e.exit_code(), 130);
  }
  interrupter.join();
  fs::remove(log);
}

TEST(RunProcess, AnAlreadyCancelledTokenStartsNothing) {
  const fs::path log = TempPath("never.log");
  const fs::path marker = TempPath("never.marker");
  CancellationToken token;
  token.Cancel(SIGINT);
  EXPECT_THROW(RunProcess({"touch", marker.string()}, log, {}, token), CancelledError);
  EXPECT_FALSE(fs::exists(marker));
  fs::remove(log);
}

// SIGKILL of arview cannot be caught: the kernel must end the child (PR_SET_PDEATHSIG).
TEST(RunProcess, TheChildDiesWithItsParentEvenBySigkill) {
  const fs::path log = TempPath("orphan.log");
  const fs::path pid_file = TempPath("orphan.pid");
  const pid_t runner = ::fork();
  ASSERT_GE(runner, 0);
  if (runner == 0) {
    try {
      RunProcess({"sh", "-c", "echo $$ > " + pid_file.string() + "; exec sleep 60"}, log, {});
    } catch (...) {
    }
    ::_exit(0);
  }
  const pid_t child = ReadPid(pid_file);
  ::kill(runner, SIGKILL);
  int status = 0;
  ::waitpid(runner, &status, 0);
  ASSERT_GT(child, 0);
  for (int i = 0; i < 100 && Alive(child); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(Alive(child)) << "the child outlived its killed parent";
  if (Alive(child)) ::kill(child, SIGKILL);
  fs::remove(log);
  fs::remove(pid_file);
}

TEST(FindExecutable, FindsShellAndRejectsUnknown) {
  EXPECT_FALSE(FindExecutable("sh").empty());
  EXPECT_TRUE(FindExecutable("arview-no-such-program-xyz").empty());
  EXPECT_TRUE(FindExecutable("/nonexistent/dir/prog").empty());
}

}  // namespace
}  // namespace arview
