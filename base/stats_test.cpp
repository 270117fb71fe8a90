#include "base/stats.h"

#include <gtest/gtest.h>

#include <cmath>

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
