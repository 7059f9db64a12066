// TimeJumpDetector and the clock checks around it: a bag restarted makes the
// scans' stamps go back; leftovers of the old timeline are stamped ahead of
// /clock. Times are passed in: no ROS master, no clock.
#include "pf_localization/ros/input/time_jump_detector.h"

#include <gtest/gtest.h>

#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {
namespace {

TEST(TimeJumpDetector, NothingBeforeTheFirstScan) {
  const TimeJumpDetector jumps;
  EXPECT_FALSE(jumps.jumpBack(ros::Time(5.0)));
}

TEST(TimeJumpDetector, AScanSlightlyOlderThanTheLastIsNoJump) {
  TimeJumpDetector jumps;
  jumps.scanUsed(ros::Time(100.0));
  EXPECT_FALSE(jumps.jumpBack(ros::Time(100.5)));
  EXPECT_FALSE(jumps.jumpBack(ros::Time(99.2)));  // 0.8 s back: within the 1 s tolerance
  EXPECT_FALSE(jumps.jumpBack(ros::Time(99.0)));  // exactly the tolerance
}

TEST(TimeJumpDetector, MoreThanTheToleranceBackIsAJumpOfThatLength) {
  TimeJumpDetector jumps;
  jumps.scanUsed(ros::Time(130.0));
  const auto back = jumps.jumpBack(ros::Time(10.0));
  ASSERT_TRUE(back);
  EXPECT_NEAR(120.0, *back, 1e-9);
  // The wider tolerance of the clock's check (it lags the messages).
  EXPECT_FALSE(jumps.jumpBack(ros::Time(128.5), kSimClockLead));
  EXPECT_TRUE(jumps.jumpBack(ros::Time(127.5), kSimClockLead));
}

TEST(TimeJumpDetector, AfterResetTheNewTimelineStartsAfresh) {
  TimeJumpDetector jumps;
  jumps.scanUsed(ros::Time(130.0));
  ASSERT_TRUE(jumps.jumpBack(ros::Time(10.0)));
  jumps.reset();
  EXPECT_FALSE(jumps.jumpBack(ros::Time(10.0)));
  jumps.scanUsed(ros::Time(10.0));
  EXPECT_FALSE(jumps.jumpBack(ros::Time(10.1)));
}

TEST(AheadOfSimClock, OnlyFurtherAheadThanTheClocksLag) {
  EXPECT_FALSE(aheadOfSimClock(ros::Time(101.9), ros::Time(100.0), true));
  const auto ahead = aheadOfSimClock(ros::Time(130.0), ros::Time(10.0), true);
  ASSERT_TRUE(ahead);
  EXPECT_NEAR(120.0, *ahead, 1e-9);
}

TEST(AheadOfSimClock, NeverWithWallTimeOrBeforeTheClockStarts) {
  // Wall time: unsynchronised computers, not a jump.
  EXPECT_FALSE(aheadOfSimClock(ros::Time(130.0), ros::Time(10.0), false));
  EXPECT_FALSE(aheadOfSimClock(ros::Time(130.0), ros::Time(), true));
}

geometry_msgs::TransformStamped link(const std::string& parent, const std::string& child,
                                     double stamp) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = ros::Time(stamp);
  t.child_frame_id = child;
  t.transform.rotation.w = 1.0;
  return t;
}

TEST(LatestChainStamp, TheNewestOfOdometryAndTheLasersMounting) {
  tf2::BufferCore tf;
  EXPECT_TRUE(latestChainStamp(tf, "odom", "base_link", "laser").isZero());
  tf.setTransform(link("base_link", "laser", 5.0), "test");
  EXPECT_EQ(ros::Time(5.0), latestChainStamp(tf, "odom", "base_link", "laser"));
  // An old-timeline odometry transform, far ahead of the others.
  tf.setTransform(link("odom", "base_link", 130.0), "test");
  EXPECT_EQ(ros::Time(130.0), latestChainStamp(tf, "odom", "base_link", "laser"));
  // Another laser's frame is not in the chain of this one.
  EXPECT_EQ(ros::Time(130.0), latestChainStamp(tf, "odom", "base_link", "other_laser"));
}

}  // namespace
}  // namespace pf_ros
