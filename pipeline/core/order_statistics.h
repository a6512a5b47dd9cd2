// Order statistics of a set of values (residuals, depths, costs, gap widths): the median and
// percentiles that robust thresholds and the stages' reports use, by partial sorting.
#pragma once

#include <algorithm>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace px {

// The value of rank min(n - 1, floor(fraction * n)) among n (0 = the smallest), for fraction in
// [0, 1]; 0 when there are none. Reorders `values`; for values kept in order, use Percentile.
template <typename T>
T PercentileInPlace(std::span<T> values, double fraction) {
  if (values.empty()) return T{0};
  const size_t rank = std::min(values.size() - 1, static_cast<size_t>(std::max(0.0, fraction) * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank), values.end());
  return values[rank];
}

// The middle value (the upper of the two middle ones for an even count); reorders `values`.
template <typename T>
T MedianInPlace(std::span<T> values) {
  return PercentileInPlace(values, 0.5);
}

template <typename T>
double Percentile(std::vector<T> values, double fraction) {
  return static_cast<double>(PercentileInPlace(std::span<T>(values), fraction));
}

template <typename T>
double Median(std::vector<T> values) {
  return Percentile(std::move(values), 0.5);
}

}  // namespace px
