// OdometryFaultTracker: the fault share follows the scan's evidence for a
// fault, within its bounds, and falls back to the floor without any.
#include "pf_localization/core/motion/odometry_fault_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
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

// `n` particles, the first `faulty` flagged, which together win `won` of
// the weight, in an update that brings a share `view` of a new view.
void adapt(OdometryFaultTracker* tracker, std::size_t n, std::size_t faulty, double won,
           const OdometryMotionParams& p, double view = 1.0) {
  tracker->flags()->assign(n, 0);
  std::vector<double> w(n);
  for (std::size_t i = 0; i < n; ++i) {
    (*tracker->flags())[i] = i < faulty ? 1 : 0;
    w[i] = i < faulty ? won / faulty : (1.0 - won) / (n - faulty);
  }
  tracker->adapt(w, p, 1, view);
}

// The weight `faulty` of `n` particles win when a scan whose whole
// evidence gives them `won` is taken to the power `view`.
double wonAtShare(std::size_t n, std::size_t faulty, double won, double view) {
  const double each = std::pow(won / faulty, view),
               other = std::pow((1.0 - won) / (n - faulty), view);
  return faulty * each / (faulty * each + (n - faulty) * other);
}

TEST(OdometryFaultTracker, AViewInPartialUpdatesMovesTheShareAsOneWholeUpdate) {
  const OdometryMotionParams p = bounds();
  // Evidence: a whole update at 0.3 from the floor, as above.
  OdometryFaultTracker whole, halves;
  whole.restart(p);
  halves.restart(p);
  adapt(&whole, 20, 1, 0.3, p);
  adapt(&halves, 20, 1, wonAtShare(20, 1, 0.3, 0.5), p, 0.5);
  // One half of a view with the evidence of half a scan believes what a
  // whole update does but for the memory of the prior (0.5^0.5 of it kept).
  EXPECT_NEAR(whole.fraction(), halves.fraction(), 0.02);
  EXPECT_GT(halves.fraction(), 0.25);
  // No evidence (the faulty particles win the share they were given): two
  // halves of a view decay towards the floor as far as one whole update.
  OdometryFaultTracker decay_whole, decay_halves;
  decay_whole.restart(p);
  decay_halves.restart(p);
  adapt(&decay_whole, 20, 1, 0.3, p);
  adapt(&decay_halves, 20, 1, 0.3, p);
  adapt(&decay_whole, 20, 6, decay_whole.fraction(), p);
  adapt(&decay_halves, 20, 6, decay_halves.fraction(), p, 0.5);
  adapt(&decay_halves, 20, 6, decay_halves.fraction(), p, 0.5);
  EXPECT_NEAR(0.05 + 0.5 * (0.3 - 0.05), decay_whole.fraction(), 1e-12);
  EXPECT_NEAR(decay_whole.fraction(), decay_halves.fraction(), 1e-12);
  // Without a new view, nothing changes.
  const double before = decay_halves.fraction();
  adapt(&decay_halves, 20, 1, 0.9, p, 0.0);
  EXPECT_EQ(before, decay_halves.fraction());
}

TEST(OdometryFaultTracker, FollowsTheScansEvidenceWithinBounds) {
  const OdometryMotionParams p = bounds();
  OdometryFaultTracker tracker;
  tracker.restart(p);
  EXPECT_EQ(0.05, tracker.fraction());
  EXPECT_FALSE(tracker.suspect(p));

  // Given 0.05 of the particles, the faulty ones won 0.3: a likelihood ratio
  // of (0.3 / 0.05) / (0.7 / 0.95) = 8.14, so 0.05 * 8.14 / (0.05 * 8.14 + 0.95).
  adapt(&tracker, 20, 1, 0.3, p);
  EXPECT_NEAR(0.3, tracker.fraction(), 1e-12);
  EXPECT_TRUE(tracker.suspect(p));
  // Given 0.3, they won 0.95 (the others are all wrong): capped.
  adapt(&tracker, 20, 6, 0.95, p);
  EXPECT_EQ(0.5, tracker.fraction());
  // None won: back to the floor.
  adapt(&tracker, 20, 10, 0.0, p);
  EXPECT_EQ(0.05, tracker.fraction());
  EXPECT_FALSE(tracker.suspect(p));
}

TEST(OdometryFaultTracker, AScanThatCannotTellThemApartKeepsTheFloor) {
  // Plain corridor walls: the faulty particles win what they were given,
  // give or take chance. Taking the share won as the next share ratcheted it
  // up to the maximum; as evidence it stays near the floor (the last
  // verdict's memory, kFaultMemory, lets chance lift it to about 0.1 at most).
  const OdometryMotionParams p = bounds();
  OdometryFaultTracker tracker;
  tracker.restart(p);
  std::mt19937 random(1);
  for (int step = 0; step < 50; ++step) {
    const double chance = random() % 2 == 0 ? 1.35 : 1.0 / 1.35;  // won a third more or less
    const double given = tracker.fraction();
    adapt(&tracker, 100, static_cast<std::size_t>(given * 100 + 0.5), chance * given, p);
    EXPECT_LT(tracker.fraction(), 0.12) << "step " << step;
  }
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
