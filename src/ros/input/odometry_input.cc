#include "pf_localization/ros/input/odometry_input.h"

#include <ros/console.h>

namespace pf_ros {

OdometryInput::OdometryInput(ros::NodeHandle& nh, const std::string& odom_frame,
                             const std::string& base_frame, tf2_ros::Buffer* buffer,
                             LimitedWarn* warn)
    : source_(odom_frame, base_frame, nh.resolveName("odom")), buffer_(buffer), warn_(warn) {
  odom_sub_ = nh.subscribe("odom", 50, &OdometryInput::onOdom, this);
  tf_watch_sub_ = nh.subscribe("/tf", 100, &OdometryInput::onTf, this);
}

void OdometryInput::onOdom(const nav_msgs::OdometryConstPtr& msg) {
  const OdometrySource::TopicMessage use = source_.onTopic(*msg);
  if (!use.problem.empty()) warn_->warn(use.problem_key, use.problem);
  if (use.transform) buffer_->setTransform(*use.transform, "odom_topic");
  announce();
}

void OdometryInput::onTf(const tf2_msgs::TFMessageConstPtr& msg) {
  if (!source_.onTf(*msg)) return;
  tf_watch_sub_.shutdown();
  odom_sub_.shutdown();
  announce();
}

void OdometryInput::announce() {
  if (const auto line = source_.takeAnnouncement()) ROS_INFO("pf_node: %s", line->c_str());
}

}  // namespace pf_ros
