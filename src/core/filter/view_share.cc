#include "pf_localization/core/filter/view_share.h"

#include <algorithm>

namespace pf {

double newViewShare(const Pose2& delta) {
  const double travel = std::hypot(delta.x, delta.y) / kViewDistance;
  const double turn = std::fabs(normalizeAngle(delta.yaw)) / kViewAngle;
  return std::min(1.0, std::max(travel, turn));
}

double leastUpdateShare(double update_min_d, double update_min_a) {
  return std::min(1.0, std::min(update_min_d / kViewDistance, update_min_a / kViewAngle));
}

}  // namespace pf
