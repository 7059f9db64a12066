// An initial pose given in another frame than the global one (odom, or
// base_link: "1 m ahead of the robot") moved into the global frame, its
// covariance rotated with it.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <tf2_ros/buffer.h>

#include <optional>
#include <string>

namespace pf_ros {

/// `pose`, given in the child frame of `frame` (a transform from tf, parent
/// -> child), in the parent frame: the pose composed onto the transform, the
/// x-y block of the covariance rotated by its yaw (R C R^T). The header is
/// left as it is, for the caller to set.
geometry_msgs::PoseWithCovarianceStamped inParentFrame(
    const geometry_msgs::PoseWithCovarianceStamped& pose,
    const geometry_msgs::TransformStamped& frame);

/// `pose` moved into `frame` through `tf`'s latest transform from its
/// frame, waiting up to `timeout` for one; the header's frame_id becomes
/// `frame`. Nothing when there is none, and `error` says why.
std::optional<geometry_msgs::PoseWithCovarianceStamped> poseInFrame(
    const tf2_ros::Buffer& tf, const geometry_msgs::PoseWithCovarianceStamped& pose,
    const std::string& frame, const ros::Duration& timeout, std::string* error);

}  // namespace pf_ros
