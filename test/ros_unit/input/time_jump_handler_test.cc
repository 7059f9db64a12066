// Time jumping back, handled in one place: a bag restarted makes the scans'
// stamps and /clock go back; leftovers of the old timeline are stamped ahead
// of /clock, at times it had reached; a player catching up is ahead of every
// clock seen. Times are passed in: no ROS master, no clock.
#include "pf_localization/ros/input/time_jump_handler.h"

#include <gtest/gtest.h>

#include <vector>

namespace pf_ros {
namespace {

geometry_msgs::TransformStamped link(const std::string& parent, const std::string& child,
                                     double stamp) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = ros::Time(stamp);
  t.child_frame_id = child;
  t.transform.rotation.w = 1.0;
  return t;
}

std_msgs::Header header(double stamp, const std::string& frame = "laser") {
  std_msgs::Header h;
  h.stamp = ros::Time(stamp);
  h.frame_id = frame;
  return h;
}

// A handler over a tf buffer that holds the robot's chain, recording each restart.
struct Fixture {
  Fixture() {
    tf.setTransform(link("odom", "base_link", 130.0), "test");
    tf.setTransform(link("base_link", "laser", 130.0), "test");
  }
  bool tfHoldsTheChain() const { return tf.canTransform("odom", "laser", ros::Time(0)); }
  tf2::BufferCore tf;
  LimitedWarn warn{"test", 5.0};
  std::vector<double> restarts;
  TimeJumpHandler jumps{&tf, "odom", "base_link", &warn,
                        [this](double back) { restarts.push_back(back); }};
};

TEST(TimeJumpHandler, NothingBeforeTheFirstScan) {
  Fixture f;
  EXPECT_FALSE(f.jumps.jumpBack(ros::Time(5.0)));
  EXPECT_TRUE(f.jumps.admitScan(ros::Time(5.0), ros::Time(), false));
  EXPECT_TRUE(f.restarts.empty());
}

TEST(TimeJumpHandler, AScanSlightlyOlderThanTheLastIsNoJump) {
  Fixture f;
  f.jumps.scanUsed(ros::Time(100.0));
  EXPECT_FALSE(f.jumps.jumpBack(ros::Time(100.5)));
  EXPECT_FALSE(f.jumps.jumpBack(ros::Time(99.2)));  // 0.8 s back: within the 1 s tolerance
  EXPECT_FALSE(f.jumps.jumpBack(ros::Time(99.0)));  // exactly the tolerance
  EXPECT_TRUE(f.jumps.admitScan(ros::Time(99.2), ros::Time(), false));
  EXPECT_TRUE(f.restarts.empty());
}

TEST(TimeJumpHandler, AScanMoreThanTheToleranceBackClearsTfAndRestartsOnce) {
  Fixture f;
  f.jumps.scanUsed(ros::Time(130.0));
  EXPECT_FALSE(f.jumps.admitScan(ros::Time(10.0), ros::Time(), false));
  ASSERT_EQ(1u, f.restarts.size());
  EXPECT_NEAR(120.0, f.restarts[0], 1e-9);
  EXPECT_FALSE(f.tfHoldsTheChain());
  // The new timeline starts afresh: its scans are used.
  EXPECT_FALSE(f.jumps.jumpBack(ros::Time(10.0)));
  EXPECT_TRUE(f.jumps.admitScan(ros::Time(10.1), ros::Time(), false));
  EXPECT_EQ(1u, f.restarts.size());
}

TEST(TimeJumpHandler, ALeftoverOfTheOldTimelineIsIgnoredWithoutASecondRestart) {
  Fixture f;
  f.jumps.clockTick(ros::Time(127.9), true);
  f.jumps.scanUsed(ros::Time(128.0));
  f.jumps.clockTick(ros::Time(10.0), true);  // the bag started over
  ASSERT_EQ(1u, f.restarts.size());
  EXPECT_NEAR(118.0, f.restarts[0], 1e-9);
  // A leftover queued before the jump, at a time the clock had reached: ignored.
  EXPECT_FALSE(f.jumps.admitScan(ros::Time(129.0), ros::Time(10.1), true));
  EXPECT_EQ(1u, f.restarts.size());
  // The new timeline's scans are used.
  EXPECT_TRUE(f.jumps.admitScan(ros::Time(10.2), ros::Time(10.2), true));
  EXPECT_EQ(1u, f.restarts.size());
}

TEST(TimeJumpHandler, ScansAheadOfALaggingClockAreUsed) {
  // rosbag play catching up after a stall: its scans and tf come seconds
  // ahead of /clock, which never goes back.
  Fixture f;
  f.jumps.clockTick(ros::Time(100.0), true);
  f.jumps.scanUsed(ros::Time(100.0));
  EXPECT_TRUE(f.jumps.admitScan(ros::Time(106.0), ros::Time(100.5), true));
  f.jumps.scanUsed(ros::Time(106.0));
  f.jumps.clockTick(ros::Time(101.0), true);
  f.jumps.scanDropped(header(104.0), ros::Time(101.0), true);
  EXPECT_TRUE(f.restarts.empty());
  EXPECT_TRUE(f.tfHoldsTheChain());  // its latest link, 130 s, is ahead of every clock seen
  // The same stamps after the clock went back from 128 s are leftovers.
  f.jumps.clockTick(ros::Time(128.0), true);
  f.jumps.clockTick(ros::Time(10.0), true);
  EXPECT_FALSE(f.jumps.admitScan(ros::Time(106.0), ros::Time(10.0), true));
  // With wall time the same stamps mean unsynchronised computers: used.
  Fixture wall;
  EXPECT_TRUE(wall.jumps.admitScan(ros::Time(129.0), ros::Time(10.0), false));
}

TEST(TimeJumpHandler, TheSimClockGoingBackRestartsWithTheWiderTolerance) {
  Fixture f;
  f.jumps.clockTick(ros::Time(130.2), true);
  f.jumps.scanUsed(ros::Time(130.0));
  f.jumps.clockTick(ros::Time(128.5), true);  // within the clock's tolerance
  f.jumps.clockTick(ros::Time(10.0), false);  // wall time: never
  EXPECT_TRUE(f.restarts.empty());
  f.jumps.clockTick(ros::Time(127.5), true);
  ASSERT_EQ(1u, f.restarts.size());
  EXPECT_NEAR(2.5, f.restarts[0], 1e-9);
  EXPECT_FALSE(f.tfHoldsTheChain());
  // Once: the clock goes on from where it went back to.
  f.jumps.clockTick(ros::Time(127.6), true);
  EXPECT_EQ(1u, f.restarts.size());
}

TEST(TimeJumpHandler, TheClockGoingBackAfterTheScansDidRestartsOnce) {
  Fixture f;
  f.jumps.clockTick(ros::Time(130.0), true);
  f.jumps.scanUsed(ros::Time(130.0));
  // The new timeline's first scan arrives before its /clock: the scans show the jump.
  EXPECT_FALSE(f.jumps.admitScan(ros::Time(10.0), ros::Time(130.0), true));
  ASSERT_EQ(1u, f.restarts.size());
  f.jumps.scanUsed(ros::Time(10.1));
  f.jumps.clockTick(ros::Time(10.1), true);
  EXPECT_EQ(1u, f.restarts.size());
}

TEST(TimeJumpHandler, OnlyTheTicksClockShowsAJump) {
  // A scan tf drops, or one used, with the node's own clock lagging the
  // ticks' in a burst: no restart, whatever their stamps.
  Fixture f;
  f.jumps.clockTick(ros::Time(130.0), true);
  f.jumps.scanUsed(ros::Time(131.0));
  f.jumps.scanDropped(header(125.0), ros::Time(125.0), true);
  EXPECT_TRUE(f.jumps.admitScan(ros::Time(131.2), ros::Time(126.0), true));
  EXPECT_TRUE(f.restarts.empty());
  EXPECT_TRUE(f.tfHoldsTheChain());
}

TEST(TimeJumpHandler, ADroppedScanClearsTfAgainWhenItHoldsTheOldTimeline) {
  Fixture f;
  f.jumps.clockTick(ros::Time(130.0), true);
  f.jumps.clockTick(ros::Time(10.0), true);
  // After the clock went back: nothing used yet, tf refilled with an old-timeline link.
  f.jumps.scanDropped(header(11.0), ros::Time(10.0), true);
  EXPECT_FALSE(f.tfHoldsTheChain());
  EXPECT_TRUE(f.restarts.empty());
  // A chain that is not ahead of the clock stays.
  f.tf.setTransform(link("odom", "base_link", 10.5), "test");
  f.tf.setTransform(link("base_link", "laser", 10.5), "test");
  f.jumps.scanDropped(header(11.0), ros::Time(10.0), true);
  EXPECT_TRUE(f.tfHoldsTheChain());
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
