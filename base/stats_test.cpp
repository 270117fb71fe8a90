#include "base/stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arview {
namespace {

TEST(Median, OddCountIsTheMiddleValue) {
  const std::vector<double> v{5, 1, 3};
  EXPECT_EQ(Median(v), 3);
}

TEST(Median, EvenCountIsTheMeanOfTheTwoMiddleValues) {
  const std::vector<double> v{4, 1, 3, 2};
  EXPECT_EQ(Median(v), 2.5);
}

TEST(Median, EmptyIsZeroAndOneValueIsItself) {
  EXPECT_EQ(Median(std::vector<double>{}), 0);
  EXPECT_EQ(Median(std::vector<double>{7.25}), 7.25);
}

TEST(Percentile, InterpolatesLinearlyBetweenRanksAsNumpy) {
  // numpy.percentile([1, 2, 3, 4, 10], [0, 25, 90, 95, 100]) = 1, 2, 7.6, 8.8, 10
  const std::vector<double> v{10, 3, 1, 4, 2};
  EXPECT_DOUBLE_EQ(Percentile(v, 0), 1);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.25), 2);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.90), 7.6);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.95), 8.8);
  EXPECT_DOUBLE_EQ(Percentile(v, 1), 10);
  EXPECT_DOUBLE_EQ(Percentile(v, 2), 10);  // clamped
  EXPECT_DOUBLE_EQ(Percentile(v, 0.5), Median(v));
}

TEST(Summarize, GivesEveryFigureFromOneDefinition) {
  const std::vector<double> v{3, 4, 0, 5};
  const Summary s = Summarize(v);
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 3);
  EXPECT_DOUBLE_EQ(s.median, 3.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt((9 + 16 + 0 + 25) / 4.0));
  EXPECT_EQ(s.min, 0);
  EXPECT_EQ(s.max, 5);
  EXPECT_DOUBLE_EQ(s.p90, Percentile(v, 0.9));
  EXPECT_DOUBLE_EQ(s.p95, Percentile(v, 0.95));
  EXPECT_DOUBLE_EQ(s.p99, Percentile(v, 0.99));
}

TEST(Summarize, EmptyInputIsAllZero) {
  const Summary s = Summarize(std::vector<double>{});
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.mean, 0);
  EXPECT_EQ(s.median, 0);
  EXPECT_EQ(s.max, 0);
}

}  // namespace
}  // namespace arview

namespace arview {
namespace {

// Count, min and max equal; the mean and RMS to rounding; each quantile within `relative` of
// the exact one (0: equal).
void ExpectSummaryWithin(const Summary& a, const Summary& exact, double relative) {
  EXPECT_EQ(a.count, exact.count);
  EXPECT_EQ(a.min, exact.min);
  EXPECT_EQ(a.max, exact.max);
  EXPECT_NEAR(a.mean, exact.mean, 1e-9 * std::abs(exact.mean));
  EXPECT_NEAR(a.rmse, exact.rmse, 1e-9 * std::abs(exact.rmse));
  for (double Summary::*q : {&Summary::median, &Summary::p90, &Summary::p95, &Summary::p99}) {
    EXPECT_NEAR(a.*q, exact.*q, relative * std::abs(exact.*q));
  }
}

TEST(StreamingSummary, UpToItsExactSamplesIsSummarizeBitForBit) {
  std::vector<double> v;
  StreamingSummary s;
  for (std::size_t i = 0; i < StreamingSummary::kExactSamples; ++i) {
    v.push_back(std::fmod(i * 0.7318, 13.0) + 0.01 * i);
    s.Add(v.back());
  }
  ASSERT_TRUE(s.exact());
  const Summary a = s.Get(), b = Summarize(v);
  ExpectSummaryWithin(a, b, 0);
  EXPECT_EQ(a.mean, b.mean);  // the same sum in the same order
  EXPECT_EQ(StreamingSummary().Get().count, 0u);
}

// A million values over six decades (log-uniform, then a heavy tail): past the exact samples,
// count, min and max are exact, the mean to rounding, and each quantile within the stated 1%.
TEST(StreamingSummary, PastItsExactSamplesQuantilesAreWithinOnePercent) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> exponent(-3.0, 3.0);
  std::vector<double> v;
  StreamingSummary s;
  for (int i = 0; i < 1000000; ++i) {
    v.push_back(i % 100 == 0 ? 5000.0 + i * 1e-3 : std::pow(10.0, exponent(rng)));
    s.Add(v.back());
  }
  ASSERT_FALSE(s.exact());
  const Summary a = s.Get(), b = Summarize(v);
  ExpectSummaryWithin(a, b, StreamingSummary::kRelativeError * (1 + 1e-9));
  // Not within a hair's breadth of exact either: the bins are what answered.
  EXPECT_NE(a.median, b.median);
}

TEST(StreamingSummary, ZeroNegativeAndHugeValuesReadAsTheExactMinimumAndMaximum) {
  StreamingSummary s;
  for (std::size_t i = 0; i <= StreamingSummary::kExactSamples; ++i) s.Add(i % 2 ? -3.0 : 0.0);
  for (std::size_t i = 0; i < 3 * StreamingSummary::kExactSamples; ++i) s.Add(1e9);
  const Summary a = s.Get();
  EXPECT_EQ(a.min, -3.0);
  EXPECT_EQ(a.max, 1e9);
  EXPECT_EQ(a.p95, 1e9);
  EXPECT_GE(a.median, -3.0);
  EXPECT_LE(a.median, 1e9);
}

}  // namespace
}  // namespace arview
