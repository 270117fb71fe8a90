#include "base/thread_priority.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <string>
#include <thread>

namespace arview {
namespace {

int NiceOfThisThread() { return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid))); }

// What the thread reports is what the kernel then says it has: the policy for real-time, the
// nice value otherwise; and it changes only the calling thread.
TEST(ThreadPriority, ATimedThreadGetsWhatItSaysAndOnlyItself) {
  int policy_before = -1, policy_after = -1, nice_after = 0;
  sched_param param{};
  std::string got;
  std::thread timed([&] {
    got = RaiseCurrentThreadForTiming(20);
    pthread_getschedparam(pthread_self(), &policy_after, &param);
    nice_after = NiceOfThisThread();
  });
  timed.join();
  sched_param mine{};
  pthread_getschedparam(pthread_self(), &policy_before, &mine);
  EXPECT_EQ(policy_before, SCHED_OTHER);  // the test's own thread is untouched
  if (got.rfind("real-time", 0) == 0) {
    EXPECT_EQ(got, "real-time (SCHED_FIFO 20)");
    EXPECT_EQ(policy_after, SCHED_FIFO);
    EXPECT_EQ(param.sched_priority, 20);
  } else if (got.rfind("nice", 0) == 0) {
    EXPECT_EQ(policy_after, SCHED_OTHER);
    EXPECT_EQ(got, "nice " + std::to_string(nice_after));
    EXPECT_LE(nice_after, -10);
  } else {
    EXPECT_EQ(got, "normal priority (real-time not permitted)");
    EXPECT_EQ(policy_after, SCHED_OTHER);
  }
}

TEST(ThreadPriority, ALoweredThreadIsNicerAndTheOthersAreNot) {
  const int before = NiceOfThisThread();
  int lowered = before;
  std::thread worker([&] {
    LowerCurrentThreadPriority(5);
    lowered = NiceOfThisThread();
  });
  worker.join();
  EXPECT_EQ(lowered, std::min(before + 5, 19));
  EXPECT_EQ(NiceOfThisThread(), before);
}

}  // namespace
}  // namespace arview
