#pragma once
// The one statistics module: every median, percentile and summary arview reports (stats.json,
// `arview eval`, the tracker's and the mapper's figures, the pipeline's stage timings, the
// benchmarks' counters) comes from here, so that the same numbers give the same figures.
//
// Definition (numpy's default, Hyndman & Fan type 7): sort the n values; the p-quantile lies at
// rank h = p·(n − 1) and is interpolated linearly between the values at floor(h) and ceil(h).
// So the median of an even count is the mean of the two middle values, Percentile(v, 0) is the
// minimum and Percentile(v, 1) the maximum. Empty input gives 0 (summaries say count = 0);
// non-finite values are the caller's to filter.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace arview {

// p in [0, 1] (clamped). Sorts a copy: O(n log n).
double Percentile(std::span<const double> values, double p);
double Median(std::span<const double> values);
double Mean(std::span<const double> values);
double Rmse(std::span<const double> values);  // sqrt(mean(v²)): the RMS of errors

// What every report quotes, from one pass over a sorted copy.
struct Summary {
  std::size_t count = 0;
  double mean = 0;
  double median = 0;
  double rmse = 0;
  double min = 0;
  double max = 0;
  double p90 = 0;
  double p95 = 0;
  double p99 = 0;
};
Summary Summarize(std::span<const double> values);

// Percentile over values already sorted ascending (no copy).
double PercentileOfSorted(std::span<const double> sorted, double p);

// A Summary of a stream of values in constant memory, for statistics that live as long as a
// session (a live `arview run` all day: 30 values a second per stage, 86 MB a day as samples).
// The first kExactSamples values are kept, and up to there Get() is Summarize() of them, bit
// for bit. Past that they move into a histogram of log-spaced bins and are dropped; from then on
//   - count, mean, rmse, min and max stay exact (a running sum, sum of squares, min, max);
//   - median, p90, p95 and p99 are within kRelativeError (1%) of the exact type-7 value, for
//     values in [kLowest, kHighest]: each order statistic the definition interpolates between
//     is replaced by its bin's representative value, which is within 1% of every value in the
//     bin, and the interpolation of two values each within 1% is within 1% of theirs. Values
//     below kLowest (zero, negatives) share one bin read as the exact minimum, values above
//     kHighest one read as the exact maximum; every quantile is clamped into [min, max].
// Memory: kExactSamples doubles (64 KiB) at most, then the bins (about 10 KiB), whatever the
// number of values.
class StreamingSummary {
 public:
  static constexpr std::size_t kExactSamples = 8192;
  static constexpr double kRelativeError = 0.01;
  // The range of the bins: milliseconds from 0.1 us to 2.8 hours, degrees from 1e-4.
  static constexpr double kLowest = 1e-4;
  static constexpr double kHighest = 1e7;

  void Add(double value);
  std::size_t count() const { return count_; }
  bool exact() const { return bins_.empty(); }  // still every value kept
  Summary Get() const;

 private:
  void MoveSamplesIntoBins();
  void AddToBins(double value);
  double Quantile(double p) const;  // from the bins
  double BinValue(std::size_t bin) const;

  std::vector<double> samples_;  // until kExactSamples values have come
  std::vector<std::uint64_t> bins_;  // [0]: below kLowest; then log-spaced; last: above kHighest
  std::size_t count_ = 0;
  double sum_ = 0, sum2_ = 0, min_ = 0, max_ = 0;
};

}  // namespace arview
