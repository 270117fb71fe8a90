#include <gtest/gtest.h>

#include <thread>

#include "app/pipeline/bounded_queue.h"
#include "app/pipeline/stage_stats.h"

namespace arview::app {
namespace {

TEST(BoundedQueue, DropOldestKeepsTheFreshestAndCountsDrops) {
  BoundedQueue<int> q(2, OverflowPolicy::kDropOldest);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(q.Push(i));
  EXPECT_EQ(q.Dropped(), 3u);
  EXPECT_EQ(*q.Pop(), 3);
  EXPECT_EQ(*q.Pop(), 4);
  q.Close();
  EXPECT_FALSE(q.Pop().has_value());
  EXPECT_FALSE(q.Push(9));
}

TEST(BoundedQueue, BlockingQueueDeliversEveryItemInOrderAcrossThreads) {
  BoundedQueue<int> q(3, OverflowPolicy::kBlock);
  std::thread producer([&] {
    for (int i = 0; i < 1000; ++i) q.Push(i);
    q.Close();
  });
  int expected = 0;
  while (auto v = q.Pop()) EXPECT_EQ(*v, expected++);
  producer.join();
  EXPECT_EQ(expected, 1000);
  EXPECT_EQ(q.Dropped(), 0u);
}

TEST(StageStats, SummariesUseBaseStatsDefinition) {
  std::vector<double> v;
  for (int i = 1; i <= 100; ++i) v.push_back(i);
  const TimingSummary s = Summarize(v);
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.median, 50.5);  // mean of the two middle samples
  EXPECT_DOUBLE_EQ(s.p95, 95.05);    // linear between ranks, as numpy.percentile
  EXPECT_DOUBLE_EQ(s.max, 100);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_EQ(Summarize({}).count, 0u);
}

TEST(StageStats, RecordsFromSeveralThreads) {
  StageStats stats;
  std::thread a([&] { for (int i = 0; i < 100; ++i) stats.Record("track", 1.0); });
  std::thread b([&] { for (int i = 0; i < 50; ++i) stats.Record("render", 2.0); });
  a.join();
  b.join();
  const auto s = stats.Summaries();
  EXPECT_EQ(s.at("track").count, 100u);
  EXPECT_DOUBLE_EQ(s.at("render").median, 2.0);
}

}  // namespace
}  // namespace arview::app
