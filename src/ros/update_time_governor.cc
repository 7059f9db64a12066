#include "pf_localization/ros/update_time_governor.h"

#include <algorithm>
#include <cmath>

namespace pf_ros {

UpdateTimeGovernor::UpdateTimeGovernor(const UpdateTimeGovernorOptions& options)
    : options_(options) {}

std::size_t UpdateTimeGovernor::addUpdate(std::size_t particles, double seconds) {
  if (!enabled()) return 0;
  if (particles == 0 || !(seconds > 0.0) || !std::isfinite(seconds)) return cap_;
  const double cost = seconds / static_cast<double>(particles);
  // A cost above the average is taken at once (the budget is exceeded now);
  // a lower one only gradually.
  cost_per_particle_ = cost_per_particle_ <= 0.0 || cost > cost_per_particle_
                           ? cost
                           : cost_per_particle_ + options_.smoothing * (cost - cost_per_particle_);
  const double target = options_.headroom * options_.max_update_time / cost_per_particle_;
  double next = std::max(target, static_cast<double>(options_.min_cap));
  if (cap_ > 0) next = std::min(next, options_.max_growth * static_cast<double>(cap_));
  next = std::max(next, static_cast<double>(options_.min_cap));
  cap_ = static_cast<std::size_t>(std::min(next, 1e12));
  return cap_;
}

}  // namespace pf_ros
