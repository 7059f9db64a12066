// An initial pose given in another frame than the global one (odom, or
// base_link: "1 m ahead of the robot") moved into the global frame, its
// covariance rotated with it; and moved on by the odometry since it was given.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <tf2/buffer_core.h>
#include <tf2_ros/buffer.h>

#include <optional>
#include <string>

#include "pf_localization/core/util/pose2.h"
#include "pf_localization/ros/diagnostics/limited_warn.h"

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
/// `frame`, its stamp the transform's. Nothing when there is none, and `error` says why.
std::optional<geometry_msgs::PoseWithCovarianceStamped> poseInFrame(
    const tf2_ros::Buffer& tf, const geometry_msgs::PoseWithCovarianceStamped& pose,
    const std::string& frame, const ros::Duration& timeout, std::string* error);

/// An initial pose (initialpose, set_map's) in `global_frame`: as it is when
/// given there, or with an empty frame_id (warned on `warn`: taken to be
/// there); moved through `tf` from any other frame, waiting up to 0.5 s for
/// the transform. Nothing, warned, when tf cannot move it.
std::optional<geometry_msgs::PoseWithCovarianceStamped> initialPoseInFrame(
    const tf2_ros::Buffer& tf, const geometry_msgs::PoseWithCovarianceStamped& pose,
    const std::string& global_frame, LimitedWarn* warn);

/// A pose given for the robot at `stamp`, as it stands at tf's latest
/// odometry (odom_frame -> base_frame), and the map -> odom that goes with it.
struct PoseNow {
  pf::Pose2 pose;
  std::optional<pf::Pose2> map_to_odom;  // none when tf has no odometry yet
};
/// `pose` moved on by the odometry since `stamp` (amcl moves an initial pose
/// the same way): a pose given while the robot drives, or with a map that
/// takes a while to build (set_map), is where the robot was when it was
/// given. Not moved when `stamp` is zero or tf has no odometry for it.
PoseNow movedByOdometrySince(const tf2::BufferCore& tf, const pf::Pose2& pose,
                             const ros::Time& stamp, const std::string& odom_frame,
                             const std::string& base_frame);

}  // namespace pf_ros
