#include "pf_localization/ros/input/pose_transform.h"

#include <Eigen/Core>
#include <cmath>

#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {

geometry_msgs::PoseWithCovarianceStamped inParentFrame(
    const geometry_msgs::PoseWithCovarianceStamped& pose,
    const geometry_msgs::TransformStamped& frame) {
  geometry_msgs::PoseWithCovarianceStamped out = pose;
  const pf::Pose2 f = toPose2(frame.transform);
  out.pose.pose = toPoseMsg(pf::compose(f, toPose2(pose.pose.pose)));
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  rot.topLeftCorner<2, 2>() << std::cos(f.yaw), -std::sin(f.yaw), std::sin(f.yaw), std::cos(f.yaw);
  out.pose.covariance =
      toRosCovariance(rot * fromRosCovariance(pose.pose.covariance) * rot.transpose());
  return out;
}

std::optional<geometry_msgs::PoseWithCovarianceStamped> poseInFrame(
    const tf2_ros::Buffer& tf, const geometry_msgs::PoseWithCovarianceStamped& pose,
    const std::string& frame, const ros::Duration& timeout, std::string* error) {
  geometry_msgs::TransformStamped t;
  try {
    t = tf.lookupTransform(frame, pose.header.frame_id, ros::Time(0), timeout);
  } catch (const tf2::TransformException& e) {
    *error = e.what();
    return std::nullopt;
  }
  geometry_msgs::PoseWithCovarianceStamped out = inParentFrame(pose, t);
  out.header.frame_id = frame;
  out.header.stamp = t.header.stamp;  // moved by the latest transform: the pose then
  return out;
}

std::optional<geometry_msgs::PoseWithCovarianceStamped> initialPoseInFrame(
    const tf2_ros::Buffer& tf, const geometry_msgs::PoseWithCovarianceStamped& pose,
    const std::string& global_frame, LimitedWarn* warn) {
  if (pose.header.frame_id.empty()) {
    warn->warn("initialpose frame",
               "initial pose with an empty frame_id: taken to be in " + global_frame);
    return pose;
  }
  if (pose.header.frame_id == global_frame) return pose;
  std::string error;
  auto moved = poseInFrame(tf, pose, global_frame, ros::Duration(0.5), &error);
  if (!moved) {
    warn->warn("initialpose tf", "ignoring the initial pose: cannot transform it from frame '" +
                                     pose.header.frame_id + "' to '" + global_frame +
                                     "': " + error);
  }
  return moved;
}

PoseNow movedByOdometrySince(const tf2::BufferCore& tf, const pf::Pose2& pose,
                             const ros::Time& stamp, const std::string& odom_frame,
                             const std::string& base_frame) {
  PoseNow out{pose, std::nullopt};
  geometry_msgs::TransformStamped latest;
  try {
    latest = tf.lookupTransform(odom_frame, base_frame, ros::Time(0));
  } catch (const tf2::TransformException&) {
    return out;  // no odometry yet (or it comes from a topic)
  }
  const pf::Pose2 odom = toPose2(latest.transform);
  if (!stamp.isZero() && stamp < latest.header.stamp) {
    try {
      const pf::Pose2 then = toPose2(tf.lookupTransform(odom_frame, base_frame, stamp).transform);
      out.pose = pf::compose(pose, pf::between(then, odom));
    } catch (const tf2::TransformException&) {
      // No odometry for then (before tf's buffer): as given.
    }
  }
  out.map_to_odom = pf::compose(out.pose, pf::inverse(odom));
  return out;
}

}  // namespace pf_ros
