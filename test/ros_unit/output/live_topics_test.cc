// pf_node's output with a ROS master (test/rostest/live_topics.test): the
// republisher's cadence under simulated time, driven by /clock, the
// latched topics that are sent only while subscribed, and the publications
// handed to the poll thread.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "pf_localization/ros/output/latched_topic.h"
#include "pf_localization/ros/output/map_to_odom_republisher.h"
#include "pf_localization/ros/output/poll_thread_outbox.h"

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
  // A bag that starts over: time jumps back, the republisher forgets and the
  // filter sets its first map -> odom again; the new timeline's first due
  // /clock publishes.
  ros::Time::setNow(at(0));
  r.reset();
  ASSERT_TRUE(r.set(mapToOdom(), at(0)));
  const std::size_t restarted = r.published();
  clockAt(&r, 50);
  EXPECT_EQ(r.published(), restarted + 1);
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

// What a thread posts inside a batch runs on roscpp's poll thread once the
// batch ends, in the order posted; before start() and after stop(), at once
// on the thread that posts.
TEST(PollThreadOutbox, ABatchRunsOnThePollThreadInOrderWhenItEnds) {
  PollThreadOutbox outbox;
  std::mutex mutex;
  std::vector<std::pair<int, std::thread::id>> ran;  // each job and where it ran
  const auto job = [&](int k) {
    return [&, k] {
      std::lock_guard<std::mutex> lock(mutex);
      ran.emplace_back(k, std::this_thread::get_id());
    };
  };
  const auto runs = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return ran;
  };
  const std::thread::id here = std::this_thread::get_id();
  outbox.post(job(0));  // not started: at once, here
  ASSERT_EQ(runs().size(), 1u);
  EXPECT_EQ(runs()[0].second, here);

  outbox.start();
  {
    PollThreadOutbox::Batch batch(&outbox);
    for (int k = 1; k <= 3; ++k) outbox.post(job(k));
    ros::WallDuration(0.2).sleep();
    EXPECT_EQ(runs().size(), 1u);  // held by the batch
  }
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(10.0);
  while (runs().size() < 4u && ros::WallTime::now() < give_up) ros::WallDuration(0.01).sleep();
  const auto batch = runs();
  ASSERT_EQ(batch.size(), 4u);
  for (int k = 1; k <= 3; ++k) {
    EXPECT_EQ(batch[k].first, k);                 // in order
    EXPECT_NE(batch[k].second, here);             // not here
    EXPECT_EQ(batch[k].second, batch[1].second);  // all on the one poll thread
  }
  outbox.stop();
  outbox.post(job(4));  // stopped: at once, here again
  ASSERT_EQ(runs().size(), 5u);
  EXPECT_EQ(runs()[4].second, here);
}

}  // namespace
}  // namespace pf_ros

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "live_topics_test");
  ros::NodeHandle keep_alive;  // the node lives for the whole test
  return RUN_ALL_TESTS();
}
