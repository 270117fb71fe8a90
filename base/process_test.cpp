#include "mapping/process.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

fs::path TempLog(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("arview_process_test_" + std::to_string(::getpid()) + "_" + name);
  fs::remove(p);
  return p;
}

TEST(RunProcess, PassesEveryLineAndTheExitCode) {
  const fs::path log = TempLog("lines.log");
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
  const fs::path log = TempLog("tail.log");
  const ProcessResult r = RunProcess({"sh", "-c", "for i in 1 2 3 4 5 6; do echo $i; done"}, log, {}, 2);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.tail, (std::vector<std::string>{"5", "6"}));
  fs::remove(log);
}

TEST(RunProcess, MissingProgramIsAClearError) {
  const fs::path log = TempLog("missing.log");
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
  const fs::path log = TempLog("signal.log");
  const ProcessResult r = RunProcess({"sh", "-c", "kill -9 $$"}, log, {});
  EXPECT_TRUE(r.signaled);
  EXPECT_EQ(r.signal, 9);
  fs::remove(log);
}

TEST(RunProcess, InterruptStopsTheChildPromptly) {
  const fs::path log = TempLog("interrupt.log");
  const fs::path pid_file = TempLog("child.pid");
  InterruptGuard guard;
  std::thread interrupter([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::kill(::getpid(), SIGINT);  // as Ctrl-C would: handled by the guard, not fatal
  });
  const auto start = std::chrono::steady_clock::now();
  // The child writes its pid, then sleeps far longer than the test may take.
  EXPECT_THROW(RunProcess({"sh", "-c", "echo $$ > " + pid_file.string() + "; exec sleep 60"}, log, {}),
               InterruptedError);
  interrupter.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
  std::ifstream in(pid_file);
  pid_t child = 0;
  ASSERT_TRUE(in >> child);
  EXPECT_NE(::kill(child, 0), 0) << "the child is still running";
  fs::remove(log);
  fs::remove(pid_file);
}

TEST(RunProcess, AnInterruptDoesNotOutliveItsGuard) {
  {
    InterruptGuard guard;
    ::kill(::getpid(), SIGINT);
    EXPECT_TRUE(InterruptGuard::Interrupted());
  }
  EXPECT_FALSE(InterruptGuard::Interrupted());
  const fs::path log = TempLog("after.log");
  EXPECT_TRUE(RunProcess({"true"}, log, {}).ok());
  fs::remove(log);
}

TEST(FindExecutable, FindsShellAndRejectsUnknown) {
  EXPECT_FALSE(FindExecutable("sh").empty());
  EXPECT_TRUE(FindExecutable("arview-no-such-program-xyz").empty());
  EXPECT_TRUE(FindExecutable("/nonexistent/dir/prog").empty());
}

}  // namespace
}  // namespace arview::mapping
