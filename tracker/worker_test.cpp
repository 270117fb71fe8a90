#include "tracker/worker.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

namespace arview::tracker {
namespace {

int ThisThreadsNice() {
  return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
}

TEST(Worker, RunsAJobOnAThreadOfLowerPriority) {
  Worker worker(5);
  const int owner = ThisThreadsNice();
  std::future<int> nice = worker.Submit<int>([] { return ThisThreadsNice(); });
  EXPECT_EQ(nice.get(), std::min(owner + 5, 19));
}

// Only the newest frame is worth the work: a job still waiting when a newer one comes is dropped.
TEST(Worker, AWaitingJobIsReplacedByANewerOne) {
  Worker worker;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> start;
  std::future<void> started = start.get_future();
  std::future<int> running = worker.Submit<int>([released, &start] {
    start.set_value();
    released.wait();
    return 1;
  });
  started.wait();
  std::future<int> dropped = worker.Submit<int>([] { return 2; });
  std::future<int> newest = worker.Submit<int>([] { return 3; });
  EXPECT_TRUE(worker.Busy());
  EXPECT_THROW(dropped.get(), std::future_error);  // broken promise
  release.set_value();
  EXPECT_EQ(running.get(), 1);
  EXPECT_EQ(newest.get(), 3);
}

TEST(Worker, DestroyedWhileAJobRunsFinishesItFirst) {
  std::atomic<bool> finished = false;
  std::future<void> job;
  {
    Worker worker;
    std::promise<void> start;
    std::future<void> started = start.get_future();
    job = worker.Submit<void>([&] {
      start.set_value();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      finished = true;
    });
    started.wait();
  }
  EXPECT_TRUE(finished);
  EXPECT_NO_THROW(job.get());
}

}  // namespace
}  // namespace arview::tracker
