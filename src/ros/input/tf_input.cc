#include "pf_localization/ros/input/tf_input.h"

#include <ros/callback_queue.h>
#include <ros/console.h>
#include <ros/this_node.h>

#include <optional>
#include <string>

namespace pf_ros {

TfInput::TfInput(const ros::NodeHandle& nh, LimitedWarn* warn)
    : buffer_(ros::Duration(30.0)), queue_(ros::getGlobalCallbackQueue()), warn_(warn) {
  ros::NodeHandle here = onPollThread(nh);
  tf_ = here.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100, [this](const ros::MessageEvent<tf2_msgs::TFMessage const>& event) {
        onTransforms(event, false);
      });
  tf_static_ = here.subscribe<tf2_msgs::TFMessage>(
      "/tf_static", 100, [this](const ros::MessageEvent<tf2_msgs::TFMessage const>& event) {
        onTransforms(event, true);
      });
}

TfInput::~TfInput() {
  tf_.shutdown();
  tf_static_.shutdown();
}

void TfInput::onTransforms(const ros::MessageEvent<tf2_msgs::TFMessage const>& event,
                           bool is_static) {
  const ros::Time now = ros::Time::now();
  if (now < last_message_) {
    ROS_WARN("pf_node: time jumped back %.3f s: tf's buffer cleared",
             (last_message_ - now).toSec());
    buffer_.clear();
  }
  last_message_ = now;
  const std::string& authority = event.getPublisherName();
  // roscpp hands this node's own messages over without a connection header
  // (their publisher reads "unknown_publisher"); another node's carry its name.
  std::optional<OwnMessageScope> own;
  if (!event.getConnectionHeaderPtr() || authority == ros::this_node::getName()) own.emplace();
  for (const geometry_msgs::TransformStamped& transform : event.getConstMessage()->transforms) {
    try {
      buffer_.setTransform(transform, authority, is_static);
    } catch (const tf2::TransformException& e) {
      warn_->warn("tf_not_stored", "a transform " + transform.header.frame_id + " -> " +
                                       transform.child_frame_id + " from " + authority +
                                       " was not stored: " + e.what());
    }
  }
}

}  // namespace pf_ros
