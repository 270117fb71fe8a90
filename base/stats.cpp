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

namespace {

// Bins of ratio gamma = (1 + a) / (1 - a): bin i (1-based) holds values in
// (kLowest·gamma^(i-1), kLowest·gamma^i], and its representative 2·kLowest·gamma^i / (gamma + 1)
// is within a = kRelativeError of every one of them (DDSketch's bound: Masson et al., VLDB 2019).
const double kGamma = (1 + StreamingSummary::kRelativeError) / (1 - StreamingSummary::kRelativeError);
const double kLogGamma = std::log(kGamma);
const std::size_t kLogBins =
    static_cast<std::size_t>(std::ceil(std::log(StreamingSummary::kHighest / StreamingSummary::kLowest) / kLogGamma));

}  // namespace

void StreamingSummary::Add(double value) {
  if (count_ == 0) min_ = max_ = value;
  min_ = std::min(min_, value);
  max_ = std::max(max_, value);
  sum_ += value;
  sum2_ += value * value;
  ++count_;
  if (exact()) {
    samples_.push_back(value);
    if (samples_.size() > kExactSamples) MoveSamplesIntoBins();
    return;
  }
  AddToBins(value);
}

void StreamingSummary::MoveSamplesIntoBins() {
  bins_.assign(kLogBins + 2, 0);
  for (double v : samples_) AddToBins(v);
  std::vector<double>().swap(samples_);  // the memory itself back, not only the size
}

void StreamingSummary::AddToBins(double value) {
  std::size_t bin;
  if (!(value > kLowest)) {
    bin = 0;  // zero, negatives, NaN
  } else if (value > kHighest) {
    bin = kLogBins + 1;
  } else {
    const double i = std::ceil(std::log(value / kLowest) / kLogGamma);
    bin = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(i, 1.0)), 1, kLogBins);
  }
  ++bins_[bin];
}

double StreamingSummary::BinValue(std::size_t bin) const {
  if (bin == 0) return min_;
  if (bin > kLogBins) return max_;
  return std::clamp(2 * kLowest * std::pow(kGamma, static_cast<double>(bin)) / (kGamma + 1), min_, max_);
}

double StreamingSummary::Quantile(double p) const {
  // Type 7 as PercentileOfSorted, with each order statistic read from its bin.
  const double h = std::clamp(p, 0.0, 1.0) * static_cast<double>(count_ - 1);
  const std::uint64_t lo = static_cast<std::uint64_t>(std::floor(h));
  const std::uint64_t hi = std::min<std::uint64_t>(lo + 1, count_ - 1);
  const double frac = h - static_cast<double>(lo);
  double lo_value = 0, hi_value = 0;
  std::uint64_t seen = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    if (bins_[bin] == 0) continue;
    const std::uint64_t next = seen + bins_[bin];
    if (lo >= seen && lo < next) lo_value = BinValue(bin);
    if (hi >= seen && hi < next) {
      hi_value = BinValue(bin);
      break;
    }
    seen = next;
  }
  return frac == 0 ? lo_value : lo_value + frac * (hi_value - lo_value);
}

Summary StreamingSummary::Get() const {
  if (exact()) return Summarize(samples_);
  Summary s;
  s.count = count_;
  s.mean = sum_ / static_cast<double>(count_);
  s.rmse = std::sqrt(sum2_ / static_cast<double>(count_));
  s.min = min_;
  s.max = max_;
  s.median = Quantile(0.5);
  s.p90 = Quantile(0.90);
  s.p95 = Quantile(0.95);
  s.p99 = Quantile(0.99);
  return s;
}

}  // namespace arview
