// pf_node's output with a ROS master (test/rostest/live_topics.test): the
// republisher's cadence under simulated time, driven by /clock, and the
// latched topics that are sent only while subscribed.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <memory>

#include "pf_localization/ros/output/latched_topic.h"
#include "pf_localization/ros/output/map_to_odom_republisher.h"

namespace pf_ros {
namespace {

geometry_msgs::TransformStamped mapToOdom() {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = "map";
  t.child_frame_id = "odom";
  t.transform.rotation.w = 1.0;
  return t;
}

// Simulated time `ms` milliseconds after 100 s.
ros::Time at(int ms) { return ros::Time(100, 0) + ros::Duration(0, ms * 1000000); }

// roscpp's clock and the republisher's /clock at `ms`.
void clockAt(MapToOdomRepublisher* r, int ms) {
  ros::Time::setNow(at(ms));
  r->onClock(at(ms));
}

TEST(MapToOdomRepublisher, UnderSimulatedTimeEachClockStepAtWhichAPeriodIsDuePublishesOnce) {
  ros::Time::setNow(at(0));  // simulated time from here on
  MapToOdomRepublisher r(MapToOdomRepublisherOptions{20.0, 0.1, true});
  ASSERT_TRUE(r.set(mapToOdom(), at(0)));
  // /clock every 10 ms for a second: one timed publication every 50 ms
  // after the update's (at 50, 100, ..., 1000 ms), none in between.
  for (int ms = 10; ms <= 1000; ms += 10) {
    clockAt(&r, ms);
    EXPECT_EQ(r.published(), 1u + static_cast<std::size_t>(ms / 50)) << "at " << ms << " ms";
  }
  // An update at 1020 ms puts the next timed publication off to 1070 ms.
  clockAt(&r, 1020);
  ASSERT_TRUE(r.set(mapToOdom(), at(1020)));
  const std::size_t after_update = r.published();
  for (int ms = 1030; ms <= 1060; ms += 10) clockAt(&r, ms);
  EXPECT_EQ(r.published(), after_update);
  clockAt(&r, 1070);
  EXPECT_EQ(r.published(), after_update + 1);
  // A bag that starts over: /clock jumps back, the republisher forgets and
  // the filter sets its first map -> odom again; the new timeline's first
  // due /clock publishes.
  clockAt(&r, 0);
  r.reset();
  ASSERT_TRUE(r.set(mapToOdom(), at(0)));
  const std::size_t restarted = r.published();
  clockAt(&r, 50);
  EXPECT_EQ(r.published(), restarted + 1);
}

TEST(MapToOdomRepublisher, UnderSimulatedTimeTheLastClockBeforeAPeriodPublishes) {
  ros::Time::setNow(at(0));
  MapToOdomRepublisher r(MapToOdomRepublisherOptions{20.0, 0.1, true});
  clockAt(&r, 0);
  ASSERT_TRUE(r.set(mapToOdom(), at(0)));
  // /clock every 40 ms (a bag at 4x): each one publishes, since the next
  // comes after the due time (50 ms after the latest publication). The first
  // /clock after it would have published every 80 ms, and after a late step
  // of 70 ms, 110 ms after the latest.
  for (int ms = 40; ms <= 400; ms += 40) {
    clockAt(&r, ms);
    EXPECT_EQ(r.published(), 1u + static_cast<std::size_t>(ms / 40)) << "at " << ms << " ms";
    EXPECT_EQ(r.lastStamp(), at(ms) + ros::Duration(0.1));
  }
  // A step of 10 ms after one of 40: the next /clock, 10 ms on, is still
  // before the due time (450 ms): no publication.
  const std::size_t before = r.published();
  r.onClock(at(410));  // roscpp's own clock still at 400 ms: it trails
  EXPECT_EQ(r.published(), before);
  // An update's map -> odom is stamped from the latest /clock (410 ms), not
  // from roscpp's trailing clock.
  ASSERT_TRUE(r.set(mapToOdom(), at(405)));
  EXPECT_EQ(r.lastStamp(), at(410) + ros::Duration(0.1));
}

TEST(LatchedTopic, KeepsTheLatestMessageForTheFirstSubscriber) {
  ros::NodeHandle nh;
  LatchedTopic<geometry_msgs::PoseWithCovarianceStamped> topic(nh, "latched_topic_test", 2);
  geometry_msgs::PoseWithCovarianceStamped first, latest;
  first.pose.pose.position.x = 1.0;
  latest.pose.pose.position.x = 2.0;
  topic.publish(first);
  topic.publish(latest);
  ASSERT_TRUE(topic.kept().has_value());  // nobody subscribes: kept, not sent
  EXPECT_EQ(topic.kept()->pose.pose.position.x, 2.0);
  // The kept message is the storage for the next one, and is kept again
  // once published.
  geometry_msgs::PoseWithCovarianceStamped spare = topic.spare();
  EXPECT_EQ(spare.pose.pose.position.x, 2.0);
  EXPECT_FALSE(topic.kept().has_value());
  topic.publish(spare);
  ASSERT_TRUE(topic.kept().has_value());

  std::vector<double> received;
  ros::Subscriber sub = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
      "latched_topic_test", 10, [&](const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
        received.push_back(msg->pose.pose.position.x);
      });
  // The connection and the message take a few spins (wall time: a bound,
  // not a measurement).
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(20.0);
  while (received.empty() && ros::WallTime::now() < give_up) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received.front(), 2.0);  // the latest, once
  EXPECT_FALSE(topic.kept().has_value());
}

}  // namespace
}  // namespace pf_ros

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "live_topics_test");
  ros::NodeHandle keep_alive;  // the node lives for the whole test
  return RUN_ALL_TESTS();
}
