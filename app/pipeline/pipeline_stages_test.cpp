#include "app/pipeline/pipeline_stages.h"

#include <gtest/gtest.h>

#include <chrono>
#include <stdexcept>
#include <thread>

namespace arview::app {
namespace {

// A stage that takes frames until its input ends or it is asked to stop, as the real ones do.
struct Consumer {
  FrameQueue& in;
  int taken = 0;
  void Run(std::stop_token stop) {
    const std::stop_callback unblock(stop, [this] { in.Close(); });
    while (auto item = in.Pop()) {
      if (stop.stop_requested()) break;
      ++taken;
    }
  }
};

struct Thrower {
  void Run(std::stop_token) { throw std::runtime_error("stage failed"); }
};

TEST(StageThread, AStopRequestEndsAStageWaitingOnItsQueueAndItJoins) {
  RunStop run;
  FrameQueue queue(2, OverflowPolicy::kBlock);
  StageThread<Consumer> stage("arview-test", run, queue);
  stage.Start();
  ASSERT_TRUE(queue.Push(InFlight{}));
  stage.RequestStop();  // it waits on an empty queue: only the stop callback can wake it
  stage.Join();
  EXPECT_TRUE(stage.IsTerminated());
  EXPECT_FALSE(run.failed());
  EXPECT_LE(stage.stage().taken, 1);
}

TEST(StageThread, AStageThatThrowsStopsTheOthersAndTheOwnerGetsItsError) {
  RunStop run;
  FrameQueue queue(2, OverflowPolicy::kBlock);
  StageThread<Consumer> waiting("arview-test", run, queue);
  waiting.Start();
  StageThread<Thrower> failing("arview-fail", run);
  failing.Start();
  failing.Join();
  waiting.Join();  // would wait forever if the failure did not stop it
  EXPECT_TRUE(waiting.IsTerminated());
  EXPECT_TRUE(run.failed());
  EXPECT_THROW(run.RethrowIfFailed(), std::runtime_error);
}

TEST(StageThread, AStageStartedAfterTheRunStoppedStopsAtOnce) {
  RunStop run;
  run.Request();
  FrameQueue queue(2, OverflowPolicy::kBlock);
  StageThread<Consumer> late("arview-test", run, queue);
  late.Start();
  late.Join();
  EXPECT_TRUE(late.IsTerminated());
  EXPECT_FALSE(queue.Push(InFlight{}));  // its stop closed its queue
}

TEST(StageThread, DestroyedWhileRunningItStopsAndJoinsBeforeItsStageGoes) {
  RunStop run;
  FrameQueue queue(2, OverflowPolicy::kBlock);
  {
    StageThread<Consumer> stage("arview-test", run, queue);
    stage.Start();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }  // std::jthread's destructor asks the stop, which closes the queue the stage waits on
  EXPECT_FALSE(queue.Push(InFlight{}));
}

}  // namespace
}  // namespace arview::app
