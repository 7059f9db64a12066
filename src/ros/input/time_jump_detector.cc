#include "pf_localization/ros/input/time_jump_detector.h"

#include <tf2/exceptions.h>

#include <algorithm>
#include <utility>

namespace pf_ros {

std::optional<double> TimeJumpDetector::jumpBack(const ros::Time& stamp, double tolerance) const {
  if (last_scan_.isZero() || stamp + ros::Duration(tolerance) >= last_scan_) return std::nullopt;
  return (last_scan_ - stamp).toSec();
}

std::optional<double> aheadOfSimClock(const ros::Time& stamp, const ros::Time& now, bool sim_time) {
  if (!sim_time) return std::nullopt;
  if (now.isZero() || stamp <= now + ros::Duration(kSimClockLead)) return std::nullopt;
  return (stamp - now).toSec();
}

ros::Time latestChainStamp(const tf2::BufferCore& tf, const std::string& odom_frame,
                           const std::string& base_frame, const std::string& laser_frame) {
  ros::Time latest;
  for (const auto& [parent, child] :
       {std::pair{odom_frame, base_frame}, std::pair{base_frame, laser_frame}}) {
    try {
      latest = std::max(latest, tf.lookupTransform(parent, child, ros::Time(0)).header.stamp);
    } catch (const tf2::TransformException&) {
      // A link missing altogether is not this problem; the scan's drop says so.
    }
  }
  return latest;
}

}  // namespace pf_ros
