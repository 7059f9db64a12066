#include "pf_localization/ros/input/scan_drop_message.h"

namespace pf_ros {
namespace {

std::string failureText(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "its stamp is older than the tf buffer";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "its frame_id is empty";
    default:
      return "no transform arrived for its stamp before the queue filled up";
  }
}

}  // namespace

std::string scanDropMessage(const std_msgs::Header& header,
                            tf2_ros::filter_failure_reasons::FilterFailureReason reason,
                            const std::string& base_frame, const std::string& odom_frame) {
  return "scan dropped: " + failureText(reason) + ". It needs tf from '" + header.frame_id +
         "' to '" + base_frame + "' (the sensor's mounting) and '" + base_frame + "' to '" +
         odom_frame + "' (odometry) at t=" + std::to_string(header.stamp.toSec()) +
         "; check that both are published";
}

}  // namespace pf_ros
