#include "pf_localization/ros/diagnostics/rolling_percentiles.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace pf_ros {

RollingPercentiles::RollingPercentiles(std::size_t window)
    : window_(std::max<std::size_t>(1, window)) {}

void RollingPercentiles::add(double value) {
  values_.push_back(value);
  while (values_.size() > window_) values_.pop_front();
}

double RollingPercentiles::percentile(double p) const {
  if (values_.empty()) return 0.0;
  std::vector<double> sorted(values_.begin(), values_.end());
  // Nearest rank: the smallest value with at least p of the values at or below it.
  const double rank = std::ceil(std::clamp(p, 0.0, 1.0) * sorted.size());
  const std::size_t k = rank < 1.0 ? 0 : static_cast<std::size_t>(rank) - 1;
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  return sorted[k];
}

double RollingPercentiles::max() const {
  return values_.empty() ? 0.0 : *std::max_element(values_.begin(), values_.end());
}

}  // namespace pf_ros
