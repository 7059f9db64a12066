// An initial pose given in another frame, moved into the global frame.
#include "pf_localization/ros/input/pose_transform.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {
namespace {

TEST(InParentFrame, ComposesThePoseAndRotatesItsCovariance) {
  geometry_msgs::TransformStamped frame;  // odom in map: 2 m east, turned a quarter left
  frame.transform.translation.x = 2.0;
  frame.transform.rotation = quaternionFromYaw(M_PI / 2);
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.frame_id = "odom";
  pose.pose.pose = toPoseMsg(pf::Pose2{1.0, 0.0, 0.1});
  pose.pose.covariance[0] = 0.04;   // xx: long along odom's x
  pose.pose.covariance[7] = 0.01;   // yy
  pose.pose.covariance[35] = 0.02;  // aa
  const auto moved = inParentFrame(pose, frame);
  const pf::Pose2 p = toPose2(moved.pose.pose);
  EXPECT_NEAR(2.0, p.x, 1e-9);
  EXPECT_NEAR(1.0, p.y, 1e-9);
  EXPECT_NEAR(M_PI / 2 + 0.1, p.yaw, 1e-9);
  // odom's x is map's y: the long axis of the covariance turns with it.
  EXPECT_NEAR(0.01, moved.pose.covariance[0], 1e-12);
  EXPECT_NEAR(0.04, moved.pose.covariance[7], 1e-12);
  EXPECT_NEAR(0.02, moved.pose.covariance[35], 1e-12);
  EXPECT_EQ("odom", moved.header.frame_id);  // for the caller to set
}

TEST(InitialPoseInFrame, KeptInTheGlobalFrameMovedFromAnotherOneRefusedWithoutTf) {
  tf2_ros::Buffer tf;
  geometry_msgs::TransformStamped odom;  // odom in map: 2 m east
  odom.header.frame_id = "map";
  odom.child_frame_id = "odom";
  odom.header.stamp = ros::Time(1.0);
  odom.transform.translation.x = 2.0;
  odom.transform.rotation.w = 1.0;
  tf.setTransform(odom, "test");
  LimitedWarn warn("test", 5.0);
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.pose.pose = toPoseMsg(pf::Pose2{1.0, 0.5, 0.1});
  for (const char* frame : {"", "map"}) {  // none (taken to be map), or map itself
    pose.header.frame_id = frame;
    const auto kept = initialPoseInFrame(tf, pose, "map", &warn);
    ASSERT_TRUE(kept) << frame;
    EXPECT_EQ(frame, kept->header.frame_id);
    EXPECT_DOUBLE_EQ(1.0, kept->pose.pose.position.x);
  }
  pose.header.frame_id = "odom";
  const auto moved = initialPoseInFrame(tf, pose, "map", &warn);
  ASSERT_TRUE(moved);
  EXPECT_EQ("map", moved->header.frame_id);
  EXPECT_NEAR(3.0, moved->pose.pose.position.x, 1e-9);
  EXPECT_NEAR(0.5, moved->pose.pose.position.y, 1e-9);
  pose.header.frame_id = "base_link";  // not in tf
  EXPECT_FALSE(initialPoseInFrame(tf, pose, "map", &warn));
}

}  // namespace
}  // namespace pf_ros
