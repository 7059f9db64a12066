#include "pf_localization/ros/localizer/update_placement.h"

#include <algorithm>

namespace pf_ros {

void UpdatePlacement::addUpdate(double wall_s, std::size_t particles) {
  recent_[seen_ % kWindow] = Update{wall_s, particles};
  ++seen_;
}

bool UpdatePlacement::onPollThread(std::size_t particles) const {
  if (seen_ < kWindow) return false;
  return std::all_of(recent_.begin(), recent_.end(), [&](const Update& u) {
    // A larger cloud costs in proportion; a smaller one is not counted on
    // to be cheaper.
    const double growth =
        std::max(1.0, static_cast<double>(particles) / std::max<std::size_t>(u.particles, 1));
    return u.wall_s * growth <= kBudget;
  });
}

}  // namespace pf_ros
