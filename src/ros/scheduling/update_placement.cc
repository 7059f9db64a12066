#include "pf_localization/ros/scheduling/update_placement.h"

#include <algorithm>

namespace pf_ros {

void UpdatePlacement::addUpdate(double wall_s, std::size_t particles) {
  wall_s_.add(wall_s);
  wall_s_per_particle_.add(wall_s / static_cast<double>(std::max<std::size_t>(particles, 1)));
}

bool UpdatePlacement::onPollThread(std::size_t particles) const {
  // A larger cloud costs in proportion; a smaller one is not counted on to be
  // cheaper.
  return wall_s_.count() == kWindow && wall_s_.max() <= kBudget &&
         static_cast<double>(particles) * wall_s_per_particle_.max() <= kBudget;
}

void UpdatePlacement::reset() {
  wall_s_ = RollingPercentiles(kWindow);
  wall_s_per_particle_ = RollingPercentiles(kWindow);
}

}  // namespace pf_ros
