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

}  // namespace arview
