#include "base/cancellation.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <thread>

namespace arview {
namespace {

TEST(CancellationToken, CopiesShareOneState) {
  CancellationToken token;
  const CancellationToken copy = token;
  EXPECT_FALSE(copy.IsCancelled());
  token.Cancel();
  EXPECT_TRUE(copy.IsCancelled());
  EXPECT_EQ(copy.Signal(), 0);
  EXPECT_TRUE(copy.flag()->load());
}

TEST(CancellationToken, ThrowIfCancelledNamesTheSignalAndGivesTheShellsExitCode) {
  CancellationToken token;
  EXPECT_NO_THROW(token.ThrowIfCancelled("x"));
  token.Cancel(SIGTERM);
  token.Cancel(SIGINT);  // the first signal is the one reported
  try {
    token.ThrowIfCancelled("out.mp4 not written");
    FAIL();
  } catch (const CancelledError& e) {
    EXPECT_EQ(e.exit_code(), 143);
    EXPECT_EQ(std::string(e.what()), "interrupted (SIGTERM): out.mp4 not written");
  }
}

TEST(ScopedSignalCancellation, SigintAndSigtermCancelTheToken) {
  for (int sig : {SIGINT, SIGTERM}) {
    ScopedSignalCancellation signals;
    ::kill(::getpid(), sig);
    EXPECT_TRUE(signals.token().IsCancelled());
    EXPECT_EQ(signals.token().Signal(), sig);
  }
}

TEST(ScopedSignalCancellation, ACancellationDoesNotOutliveItsScopeAndHandlersComeBack) {
  struct sigaction before {};
  ::sigaction(SIGTERM, nullptr, &before);
  {
    ScopedSignalCancellation signals;
    ::kill(::getpid(), SIGTERM);
    EXPECT_TRUE(signals.token().IsCancelled());
  }
  struct sigaction after {};
  ::sigaction(SIGTERM, nullptr, &after);
  EXPECT_EQ(before.sa_handler, after.sa_handler);
  ScopedSignalCancellation next;
  EXPECT_FALSE(next.token().IsCancelled());
}

TEST(ScopedSignalCancellation, OnlyOneAtATime) {
  ScopedSignalCancellation signals;
  EXPECT_THROW(ScopedSignalCancellation second, std::logic_error);
}

// The handler is installed without SA_RESTART: a blocked read returns EINTR so that the
// caller looks at the token instead of waiting for input that may never come.
TEST(ScopedSignalCancellation, InterruptsABlockingRead) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ScopedSignalCancellation signals;
  const pthread_t reader = ::pthread_self();
  std::thread interrupter([reader] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::pthread_kill(reader, SIGINT);
  });
  char c;
  const ssize_t n = ::read(fds[0], &c, 1);
  const int err = errno;
  interrupter.join();
  EXPECT_EQ(n, -1);
  EXPECT_EQ(err, EINTR);
  EXPECT_TRUE(signals.token().IsCancelled());
  ::close(fds[0]);
  ::close(fds[1]);
}

}  // namespace
}  // namespace arview
