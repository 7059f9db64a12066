// What pf_node says when tf2's message filter drops a scan: why, and which
// transforms the scan needs, so that the user can check that both are
// published. Also lowers the priority of the calling thread (pf_node's
// filter thread), so that the filter yields the CPU to tf and odometry.
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

/// Raises the calling thread's nice value by `increment` (at most to 19),
/// which the threads it starts later inherit (OpenMP's). Needs no
/// privilege; failing, it changes nothing.
void lowerThreadPriority(int increment);

}  // namespace pf_ros
