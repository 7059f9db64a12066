// pf_node's odometry (odom -> base) as it reaches the tf buffer: watches /tf
// until it shows whether odometry travels there, and takes the odometry
// topic's messages into the buffer while it does not (OdometrySource
// decides). Once tf is the source, neither is subscribed any more: the
// topic's messages (twice the scans' rate, often) no longer wake the node.
// Which source is in use is logged once, and again when it changes. Its
// callbacks run on the main spinner.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/node_handle.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>

#include <string>

#include "pf_localization/ros/diagnostics/limited_warn.h"
#include "pf_localization/ros/input/odometry_source.h"

namespace pf_ros {

class OdometryInput {
 public:
  /// Subscribes `odom` and /tf on `nh`. `buffer` and `warn` (the topic's bad
  /// messages) must outlive it.
  OdometryInput(ros::NodeHandle& nh, const std::string& odom_frame, const std::string& base_frame,
                tf2_ros::Buffer* buffer, LimitedWarn* warn);

 private:
  void onOdom(const nav_msgs::OdometryConstPtr& msg);
  void onTf(const tf2_msgs::TFMessageConstPtr& msg);
  void announce();

  OdometrySource source_;
  tf2_ros::Buffer* buffer_;
  LimitedWarn* warn_;
  ros::Subscriber odom_sub_, tf_watch_sub_;  // subscribed in the constructor's body
};

}  // namespace pf_ros
