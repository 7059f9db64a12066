#include "pf_localization/ros/output/republish_schedule.h"

namespace pf_ros {

bool RepublishSchedule::due(const ros::Time& now, const ros::Duration& period,
                            const ros::Time& next_chance) {
  if (next_.isZero() || now + period < next_) next_ = now;
  return now >= next_ || next_chance > next_;
}

}  // namespace pf_ros
