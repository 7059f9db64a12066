// What pf_node says when tf2's message filter drops a scan: why, and which
// transforms the scan needs, so that the user can check that both are
// published.
#pragma once

#include <std_msgs/Header.h>
#include <tf2_ros/message_filter.h>

#include <string>

namespace pf_ros {

/// The warning for a scan or cloud with `header` dropped for `reason`, the
/// robot's frames being `base_frame` and `odom_frame`.
std::string scanDropMessage(const std_msgs::Header& header,
                            tf2_ros::filter_failure_reasons::FilterFailureReason reason,
                            const std::string& base_frame, const std::string& odom_frame);

}  // namespace pf_ros
