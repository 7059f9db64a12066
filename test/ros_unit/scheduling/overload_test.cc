// The pieces of pf_node's overload handling that need no ROS master: the one-scan hand-over, the
// latency percentiles, the particle cap of max_update_time, the bounded particle cloud and the
// rate-limited log.
#include <gtest/gtest.h>

#include <boost/make_shared.hpp>
#include <map>
#include <thread>

#include "pf_localization/ros/diagnostics/limited_log.h"
#include "pf_localization/ros/diagnostics/update_timing.h"
#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/scheduling/latest_scan_slot.h"
#include "pf_localization/ros/scheduling/update_time_governor.h"
#include "ros_unit/test_messages.h"

namespace pf_ros {
namespace {

using test::scanStamped;

TEST(LatestScanSlot, TheNewestScanWinsAndTheOlderOneIsCounted) {
  LatestScanSlot slot;
  EXPECT_FALSE(slot.put(scanStamped(1.0)));
  EXPECT_TRUE(slot.put(scanStamped(2.0)));
  EXPECT_TRUE(slot.put(scanStamped(3.0)));
  EXPECT_EQ(slot.dropped(), 2u);
  const auto taken = slot.take(ros::WallDuration(0.0));
  ASSERT_TRUE(taken.has_value());
  EXPECT_EQ(taken->scan->header.stamp, ros::Time(3.0));
  // Taken: nothing waits any more, and the next scan replaces nothing.
  EXPECT_FALSE(slot.take(ros::WallDuration(0.0)).has_value());
  EXPECT_FALSE(slot.put(scanStamped(4.0)));
  EXPECT_EQ(slot.dropped(), 2u);
}

TEST(LatestScanSlot, EachSensorKeepsItsNewestScanAndTheFirstToArriveGoesFirst) {
  LatestScanSlot slot;
  EXPECT_FALSE(slot.put(scanStamped(1.0, 0)));
  EXPECT_FALSE(slot.put(scanStamped(1.05, 1)));  // the other lidar: nothing dropped
  EXPECT_TRUE(slot.put(scanStamped(1.1, 0)));    // the first lidar's 1.0 is
  EXPECT_EQ(slot.dropped(), 1u);
  auto taken = slot.take(ros::WallDuration(0.0));
  ASSERT_TRUE(taken.has_value());
  EXPECT_EQ(taken->sensor, 1u);
  EXPECT_EQ(taken->scan->header.stamp, ros::Time(1.05));
  taken = slot.take(ros::WallDuration(0.0));
  ASSERT_TRUE(taken.has_value());
  EXPECT_EQ(taken->sensor, 0u);
  EXPECT_EQ(taken->scan->header.stamp, ros::Time(1.1));
  EXPECT_FALSE(slot.take(ros::WallDuration(0.0)).has_value());
}

TEST(LatestScanSlot, TakeWaitsForAScanFromAnotherThreadAndCloseWakesIt) {
  LatestScanSlot slot;
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    slot.put(scanStamped(5.0));
  });
  const auto taken = slot.take(ros::WallDuration(10.0));
  producer.join();
  ASSERT_TRUE(taken.has_value());
  EXPECT_EQ(taken->scan->header.stamp, ros::Time(5.0));
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    slot.close();
  });
  const ros::WallTime start = ros::WallTime::now();
  EXPECT_FALSE(slot.take(ros::WallDuration(10.0)).has_value());
  closer.join();
  EXPECT_LT((ros::WallTime::now() - start).toSec(), 5.0);
  EXPECT_TRUE(slot.closed());
}

TEST(LatestScanSlot, IdleOnlyWhenNothingWaitsAndTheScanTakenIsDone) {
  LatestScanSlot slot;
  EXPECT_TRUE(slot.idle());
  slot.put(scanStamped(1.0));
  EXPECT_FALSE(slot.idle());  // waiting
  ASSERT_TRUE(slot.take(ros::WallDuration(0.0)).has_value());
  EXPECT_FALSE(slot.idle());  // in the filter thread's hands: a newer scan must not overtake it
  slot.done();
  EXPECT_TRUE(slot.idle());
  slot.done();  // one too many changes nothing
  slot.put(scanStamped(2.0));
  EXPECT_FALSE(slot.idle());
}

TEST(LatestScanSlot, TakeUnclaimedOnlyWhenNoneIsInHand) {
  LatestScanSlot slot;
  EXPECT_FALSE(slot.takeUnclaimed().has_value());
  slot.put(scanStamped(1.0));
  slot.put(scanStamped(2.0, 1));
  ASSERT_TRUE(slot.take(ros::WallDuration(0.0)).has_value());
  // Scan 1 is in the filter thread's hands: the other sensor's must not overtake it.
  EXPECT_FALSE(slot.takeUnclaimed().has_value());
  slot.done();
  const auto taken = slot.takeUnclaimed();
  ASSERT_TRUE(taken.has_value());
  EXPECT_EQ(2.0, taken->header().stamp.toSec());
  EXPECT_TRUE(slot.idle());  // not in hand: its taker handles it there and then
  EXPECT_EQ(0u, slot.dropped());
}

TEST(RollingPercentiles, NearestRankOverTheLastWindow) {
  RollingPercentiles r(100);
  EXPECT_EQ(r.percentile(0.5), 0.0);
  EXPECT_EQ(r.max(), 0.0);
  for (int i = 1; i <= 200; ++i) r.add(i);
  // Only 101..200 remain.
  EXPECT_EQ(r.count(), 100u);
  EXPECT_EQ(r.percentile(0.5), 150.0);
  EXPECT_EQ(r.percentile(0.95), 195.0);
  EXPECT_EQ(r.percentile(0.0), 101.0);
  EXPECT_EQ(r.max(), 200.0);
}

TEST(UpdateTiming, ReportsPercentilesInMsDroppedScansAndTheCap) {
  UpdateTiming timing(UpdateTimingOptions{10});
  for (int i = 1; i <= 10; ++i) timing.addUpdate(0.01 * i, 0.001 * i, 0.005 * i);
  EXPECT_DOUBLE_EQ(timing.updateTimeP95(), 0.05);
  diagnostic_msgs::DiagnosticStatus status;
  timing.addTo(&status, 7, 1234);
  std::map<std::string, std::string> v;
  for (const auto& kv : status.values) v[kv.key] = kv.value;
  EXPECT_EQ(v.at("latency_p50_ms"), "50.0");
  EXPECT_EQ(v.at("latency_p95_ms"), "100.0");
  EXPECT_EQ(v.at("latency_max_ms"), "100.0");
  EXPECT_EQ(v.at("scan_age_p50_ms"), "5.0");
  EXPECT_EQ(v.at("update_time_max_ms"), "50.0");
  EXPECT_EQ(v.at("dropped_scans"), "7");
  EXPECT_EQ(v.at("particle_cap"), "1234");
  diagnostic_msgs::DiagnosticStatus without_cap;
  timing.addTo(&without_cap, 0);
  for (const auto& kv : without_cap.values) EXPECT_NE(kv.key, "particle_cap");
}

TEST(UpdateTimeGovernor, OffByDefault) {
  UpdateTimeGovernor g;
  EXPECT_FALSE(g.enabled());
  EXPECT_EQ(g.addUpdate(1000000, 0.2), 0u);
  EXPECT_EQ(g.cap(), 0u);
}

TEST(UpdateTimeGovernor, CapsTheCountToTheBudgetAndFollowsTheLoad) {
  UpdateTimeGovernorOptions o;
  o.max_update_time = 0.02;
  UpdateTimeGovernor g(o);
  // 1 000 000 particles in 160 ms: 160 ns each; 60 % of 20 ms is 75 000.
  EXPECT_NEAR(static_cast<double>(g.addUpdate(1000000, 0.16)), 75000.0, 1.0);
  // Twice as slow (another process took a core): halved at once.
  EXPECT_NEAR(static_cast<double>(g.addUpdate(75000, 0.024)), 37500.0, 1.0);
  // The CPU is free again: the cap grows back, 25 % per update at most.
  std::size_t cap = g.cap();
  for (int i = 0; i < 40; ++i) {
    const std::size_t next = g.addUpdate(cap, cap * 160e-9);
    EXPECT_LE(next, static_cast<std::size_t>(1.25 * cap) + 1);
    cap = next;
  }
  EXPECT_NEAR(static_cast<double>(cap), 75000.0, 1000.0);
  // A single slow update is an outlier of the window's p95 (its second
  // largest of 20); two of them are a new load. Never below min_cap.
  EXPECT_NEAR(static_cast<double>(g.addUpdate(100, 10.0)), 75000.0, 1000.0);
  EXPECT_EQ(g.addUpdate(100, 10.0), o.min_cap);
  // Nonsense measurements change nothing.
  EXPECT_EQ(g.addUpdate(0, 0.01), o.min_cap);
  EXPECT_EQ(g.addUpdate(100, -1.0), o.min_cap);
}

pf::ParticleSet cloud(std::size_t n) {
  pf::ParticleSet p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.setPose(i, {static_cast<double>(i), 0.0, 0.0});
  p.setUniformWeights();
  return p;
}

TEST(ToPoseArray, SmallCloudsAndZeroLimitAreSentWhole) {
  geometry_msgs::PoseArray out;
  toPoseArray(cloud(10), 100, &out);
  EXPECT_EQ(out.poses.size(), 10u);
  toPoseArray(cloud(1000), 0, &out);
  EXPECT_EQ(out.poses.size(), 1000u);
}

TEST(ToPoseArray, LargeCloudIsASystematicResampleByWeight) {
  pf::ParticleSet p = cloud(100000);
  geometry_msgs::PoseArray out;
  toPoseArray(p, 1000, &out);
  ASSERT_EQ(out.poses.size(), 1000u);
  // Uniform weights: evenly spread over the cloud.
  EXPECT_NEAR(out.poses.front().position.x, 49.5, 1.0);
  EXPECT_NEAR(out.poses.back().position.x, 99949.5, 1.0);
  // All the weight on the last tenth: every pose comes from there.
  for (std::size_t i = 0; i < p.size(); ++i) p.weight[i] = i >= 90000 ? 1.0 : 0.0;
  toPoseArray(p, 1000, &out);
  ASSERT_EQ(out.poses.size(), 1000u);
  for (const auto& pose : out.poses) EXPECT_GE(pose.position.x, 90000.0);
  // Weights that are no use: every n-th particle.
  for (double& w : p.weight) w = 0.0;
  toPoseArray(p, 1000, &out);
  ASSERT_EQ(out.poses.size(), 1000u);
  EXPECT_EQ(out.poses[1].position.x, 100.0);
}

TEST(LimitedLog, OneLinePerKindAndPeriodCountingTheRest) {
  LimitedLog log(5.0);
  int suppressed = -1;
  EXPECT_TRUE(log.due("a", 100.0, &suppressed));
  EXPECT_EQ(suppressed, 0);
  EXPECT_FALSE(log.due("a", 101.0));
  EXPECT_FALSE(log.due("a", 104.0));
  EXPECT_TRUE(log.due("b", 104.0));
  EXPECT_TRUE(log.due("a", 105.5, &suppressed));
  EXPECT_EQ(suppressed, 2);
}

}  // namespace
}  // namespace pf_ros
