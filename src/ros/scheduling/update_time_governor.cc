#include "pf_localization/ros/scheduling/update_time_governor.h"

#include <algorithm>
#include <cmath>

namespace pf_ros {

UpdateTimeGovernor::UpdateTimeGovernor(const UpdateTimeGovernorOptions& options)
    : options_(options), cost_per_particle_(options.window) {}

std::size_t UpdateTimeGovernor::addUpdate(std::size_t particles, double seconds) {
  if (!enabled()) return 0;
  if (particles == 0 || !(seconds > 0.0) || !std::isfinite(seconds)) return cap_;
  cost_per_particle_.add(seconds / static_cast<double>(particles));
  const double cost = cost_per_particle_.percentile(options_.quantile);
  const double target = options_.headroom * options_.max_update_time / cost;
  double next = std::max(target, static_cast<double>(options_.min_cap));
  if (cap_ > 0) next = std::min(next, options_.max_growth * static_cast<double>(cap_));
  next = std::max(next, static_cast<double>(options_.min_cap));
  cap_ = static_cast<std::size_t>(std::min(next, 1e12));
  return cap_;
}

}  // namespace pf_ros
