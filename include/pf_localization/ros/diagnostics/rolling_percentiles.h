// A window over the latest values of a figure (an update's wall time, a
// scan's latency) and its quantiles: what the diagnostics report, and what
// UpdatePlacement and UpdateTimeGovernor decide from. Not thread-safe.
#pragma once

#include <cstddef>
#include <deque>

namespace pf_ros {

/// p50 / p95 / max of the last `window` values added.
class RollingPercentiles {
 public:
  explicit RollingPercentiles(std::size_t window);
  void add(double value);
  std::size_t count() const { return values_.size(); }
  /// The nearest-rank `p` quantile (p in [0, 1]) of the window; 0 when empty.
  double percentile(double p) const;
  double max() const;

 private:
  std::size_t window_;
  std::deque<double> values_;
};

}  // namespace pf_ros
