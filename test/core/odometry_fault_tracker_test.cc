// OdometryFaultTracker: the fault share follows the weight the faulty
// particles win, within its bounds.
#include "pf_localization/core/odometry_fault_tracker.h"

#include <gtest/gtest.h>

#include <vector>

namespace pf {
namespace {

OdometryMotionParams bounds() {
  OdometryMotionParams p;
  p.fault_fraction = 0.05;
  p.fault_fraction_max = 0.5;
  p.fault_suspect_fraction = 0.3;
  p.fault_margin = 0.2;
  return p;
}

TEST(OdometryFaultTracker, FollowsTheWeightTheFaultyParticlesWinWithinBounds) {
  const OdometryMotionParams p = bounds();
  OdometryFaultTracker tracker;
  tracker.restart(p);
  EXPECT_EQ(0.05, tracker.fraction());
  EXPECT_FALSE(tracker.suspect(p));

  *tracker.flags() = {1, 0, 1, 0};
  tracker.adapt({0.2, 0.4, 0.2, 0.2}, p);  // the faulty ones won 0.4
  EXPECT_DOUBLE_EQ(0.4, tracker.fraction());
  EXPECT_TRUE(tracker.suspect(p));

  tracker.adapt({0.45, 0.05, 0.45, 0.05}, p);  // 0.9: capped
  EXPECT_EQ(0.5, tracker.fraction());
  tracker.adapt({0.0, 0.5, 0.0, 0.5}, p);  // none: back to the floor
  EXPECT_EQ(0.05, tracker.fraction());
  EXPECT_FALSE(tracker.suspect(p));
}

TEST(OdometryFaultTracker, NewBoundsClampTheShare) {
  OdometryMotionParams p = bounds();
  OdometryFaultTracker tracker;
  tracker.restart(p);
  *tracker.flags() = {1, 0};
  tracker.adapt({0.4, 0.6}, p);
  p.fault_fraction_max = 0.25;
  tracker.clampTo(p);
  EXPECT_EQ(0.25, tracker.fraction());
  p.fault_fraction = 0.3;
  p.fault_fraction_max = 0.5;
  tracker.clampTo(p);
  EXPECT_EQ(0.3, tracker.fraction());
}

TEST(OdometryFaultTracker, OnlyAStepOfHalfTheMarginShowsFaults) {
  const OdometryMotionParams p = bounds();  // fault_margin 0.2 m
  EXPECT_FALSE(OdometryFaultTracker::observable(0.09, p));
  EXPECT_TRUE(OdometryFaultTracker::observable(0.1, p));
  EXPECT_TRUE(OdometryFaultTracker::observable(1.0, p));
}

TEST(OdometryFaultTracker, ReserveKeepsTheFlags) {
  OdometryFaultTracker tracker;
  *tracker.flags() = {1, 0, 1};
  tracker.reserve(1000);
  EXPECT_EQ((std::vector<uint8_t>{1, 0, 1}), *tracker.flags());
  EXPECT_GE(tracker.flags()->capacity(), 1000u);
}

}  // namespace
}  // namespace pf
