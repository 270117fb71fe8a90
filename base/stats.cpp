#include "base/stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace arview {
namespace {

std::vector<double> Sorted(std::span<const double> values) {
  std::vector<double> v(values.begin(), values.end());
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

double PercentileOfSorted(std::span<const double> sorted, double p) {
  if (sorted.empty()) return 0;
  const double h = std::clamp(p, 0.0, 1.0) * static_cast<double>(sorted.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(h));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double frac = h - static_cast<double>(lo);
  // Written so that equal neighbours give exactly that value (no rounding from the blend).
  return frac == 0 ? sorted[lo] : sorted[lo] + frac * (sorted[hi] - sorted[lo]);
}

double Percentile(std::span<const double> values, double p) { return PercentileOfSorted(Sorted(values), p); }

double Median(std::span<const double> values) { return Percentile(values, 0.5); }

double Mean(std::span<const double> values) {
  if (values.empty()) return 0;
  return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

double Rmse(std::span<const double> values) {
  if (values.empty()) return 0;
  double sum2 = 0;
  for (double v : values) sum2 += v * v;
  return std::sqrt(sum2 / static_cast<double>(values.size()));
}

Summary Summarize(std::span<const double> values) {
  Summary s;
  s.count = values.size();
  if (values.empty()) return s;
  const std::vector<double> sorted = Sorted(values);
  s.mean = Mean(values);  // in the caller's order, as a plain mean is summed
  s.rmse = Rmse(values);
  s.min = sorted.front();
  s.max = sorted.back();
  s.median = PercentileOfSorted(sorted, 0.5);
  s.p90 = PercentileOfSorted(sorted, 0.90);
  s.p95 = PercentileOfSorted(sorted, 0.95);
  s.p99 = PercentileOfSorted(sorted, 0.99);
  return s;
}

}  // namespace arview
