// UpdateGate: which scans run a filter update, and the reason of each skip.
#include "pf_localization/core/filter/update_gate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "core/small_world.h"
#include "pf_localization/core/filter/view_share.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"

namespace pf {
namespace {

using small_world::castScan;
using small_world::kTruth;

class UpdateGateTest : public ::testing::Test {
 protected:
  UpdateGateTest() : grid_(small_world::room()), model_(grid_, LikelihoodFieldModelParams()) {
    params_.update_fit_drop = 0.0;  // the thresholds alone, unless a test says otherwise
  }

  GateDecision decide(const Pose2& odom, const Pose2& robot, bool suspect = false) {
    return gate_.decide(odom, castScan(grid_, robot), &model_, true, robot, suspect, params_);
  }

  OccupancyGrid grid_;
  LikelihoodFieldModel model_;
  ParticleFilterParams params_;  // update_min_d 0.2 m, update_min_a pi/6, odom_jump_limit 5 m
  UpdateGate gate_;
};

TEST(OneUpdateStep, IsTwiceTheThresholdsAndUnboundedWithout) {
  ParticleFilterParams params;  // 0.2 m, pi / 6
  EXPECT_DOUBLE_EQ(0.4, oneUpdateStep(params).distance);
  EXPECT_DOUBLE_EQ(M_PI / 3, oneUpdateStep(params).angle);
  params.update_min_d = 0.0;  // every scan updates
  params.update_min_a = 0.0;
  EXPECT_EQ(std::numeric_limits<double>::infinity(), oneUpdateStep(params).distance);
  EXPECT_EQ(std::numeric_limits<double>::infinity(), oneUpdateStep(params).angle);
}

TEST_F(UpdateGateTest, InputChecksComeFirstAndSayWhich) {
  const LaserScan scan = castScan(grid_, kTruth);
  EXPECT_EQ(SkipReason::kNoMap,
            gate_.decide(kTruth, scan, nullptr, true, kTruth, false, params_).skip_reason);
  EXPECT_EQ(SkipReason::kNotInitialized,
            gate_.decide(kTruth, scan, &model_, false, kTruth, false, params_).skip_reason);
  const Pose2 nan{std::nan(""), 0.0, 0.0};
  EXPECT_EQ(SkipReason::kOdometryNotFinite,
            gate_.decide(nan, scan, &model_, true, kTruth, false, params_).skip_reason);
  LaserScan bad = scan;
  bad.angle_increment = 0.0;
  const GateDecision d = gate_.decide(kTruth, bad, &model_, true, kTruth, false, params_);
  EXPECT_EQ(SkipReason::kBadScan, d.skip_reason);
  EXPECT_EQ(*validateScan(bad), d.skip_detail);
  // None of them counted as an update.
  EXPECT_FALSE(gate_.hasUpdated());
  EXPECT_FALSE(gate_.odomAtUpdate().has_value());
}

TEST_F(UpdateGateTest, TheFirstScanRunsWithoutMotionThenOnlyAfterMotion) {
  const Pose2 odom0{5.0, 5.0, 2.0};
  GateDecision d = decide(odom0, kTruth);
  ASSERT_TRUE(d.runs()) << toString(d.skip_reason);
  EXPECT_FALSE(d.from.has_value());
  ASSERT_TRUE(d.scans.has_value());
  EXPECT_GT(beamCount(*d.scans), 0u);
  EXPECT_TRUE(gate_.hasUpdated());

  EXPECT_EQ(SkipReason::kNotMoved, decide(odom0, kTruth).skip_reason);
  EXPECT_EQ(SkipReason::kNotMoved, decide(compose(odom0, {0.19, 0.0, 0.0}), kTruth).skip_reason);
  EXPECT_EQ(SkipReason::kNotMoved, decide(compose(odom0, {0.0, 0.0, 0.5}), kTruth).skip_reason);

  const Pose2 odom1 = compose(odom0, {0.0, -0.21, 0.0});
  d = decide(odom1, kTruth);
  ASSERT_TRUE(d.runs()) << toString(d.skip_reason);
  ASSERT_TRUE(d.from.has_value());
  EXPECT_EQ(odom0.x, d.from->x);
  EXPECT_NEAR(0.21, d.step, 1e-9);
  EXPECT_FALSE(d.fit_dropped);
  // The reference is now odom1: turning 0.55 rad from there is enough.
  EXPECT_TRUE(decide(compose(odom1, {0.0, 0.0, 0.55}), kTruth).runs());
}

TEST_F(UpdateGateTest, ARequestedUpdateOrSuspectOdometryRunsWithoutMotion) {
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  gate_.requestUpdate();
  EXPECT_TRUE(decide(odom, kTruth).runs());
  EXPECT_EQ(SkipReason::kNotMoved, decide(odom, kTruth).skip_reason);  // once
  EXPECT_TRUE(decide(odom, kTruth, /*suspect=*/true).runs());
}

TEST_F(UpdateGateTest, AnOdometryJumpIsSkippedAndTrackingResumesFromIt) {
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  const Pose2 jumped = compose(odom, {10.0, 0.0, 0.0});
  const GateDecision d = decide(jumped, kTruth);
  EXPECT_EQ(SkipReason::kOdometryJumped, d.skip_reason);
  EXPECT_NEAR(10.0, d.step, 1e-9);
  EXPECT_EQ(jumped.x, gate_.odomAtUpdate()->x);
  // Measured from the new odometry, the robot has not moved.
  EXPECT_EQ(SkipReason::kNotMoved, decide(jumped, kTruth).skip_reason);
}

TEST_F(UpdateGateTest, AScanWithoutValidBeamKeepsTheReference) {
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  LaserScan blind = castScan(grid_, kTruth);
  blind.ranges.assign(blind.ranges.size(), std::numeric_limits<float>::quiet_NaN());
  const Pose2 moved = compose(odom, {0.5, 0.0, 0.0});
  const GateDecision d = gate_.decide(moved, blind, &model_, true, kTruth, false, params_);
  EXPECT_EQ(SkipReason::kNoValidBeam, d.skip_reason);
  ASSERT_TRUE(d.scans.has_value());
  EXPECT_EQ(180, droppedBeams(*d.scans));
  EXPECT_EQ(odom.x, gate_.odomAtUpdate()->x);
  // The motion is applied with the next usable scan, from the old reference.
  const GateDecision next = decide(moved, kTruth);
  ASSERT_TRUE(next.runs());
  EXPECT_EQ(odom.x, next.from->x);
}

TEST_F(UpdateGateTest, AScanThatStopsFittingRunsBeforeTheThresholds) {
  params_.update_fit_drop = 0.2;
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  const LaserScan at_truth = castScan(grid_, kTruth);
  gate_.recordFit(model_, {model_.prepare(at_truth)}, kTruth, params_);
  // 5 cm of odometry, and the scan still fits the predicted pose: waits.
  const Pose2 step{0.05, 0.0, 0.0};
  EXPECT_EQ(SkipReason::kNotMoved,
            gate_
                .decide(compose(odom, step), castScan(grid_, compose(kTruth, step)), &model_, true,
                        kTruth, false, params_)
                .skip_reason);
  // The robot was pushed 0.4 m while the odometry says 5 cm: runs now.
  const GateDecision d =
      gate_.decide(compose(odom, step), castScan(grid_, compose(kTruth, {0.45, 0.3, 0.0})), &model_,
                   true, kTruth, false, params_);
  EXPECT_TRUE(d.runs()) << toString(d.skip_reason);
  EXPECT_TRUE(d.fit_dropped);
}

TEST(NewViewShare, IsTheLargerOfTravelAndTurnOverAViewAtMostOne) {
  EXPECT_DOUBLE_EQ(0.0, newViewShare({0.0, 0.0, 0.0}));
  EXPECT_DOUBLE_EQ(0.25, newViewShare({0.05, 0.0, 0.0}));
  EXPECT_DOUBLE_EQ(0.25, newViewShare({0.0, -0.05, 0.0}));
  EXPECT_DOUBLE_EQ(0.5, newViewShare({0.0, 0.0, -M_PI / 12}));
  EXPECT_DOUBLE_EQ(0.5, newViewShare({0.05, 0.0, M_PI / 12}));  // the turn
  EXPECT_DOUBLE_EQ(1.0, newViewShare({0.2, 0.0, 0.0}));
  EXPECT_DOUBLE_EQ(1.0, newViewShare({3.0, 0.0, 2.0}));
}

TEST_F(UpdateGateTest, AnUpdateCarriesTheShareOfANewViewItsMotionBrings) {
  params_.update_min_d = params_.update_min_a = 0.0;  // every scan updates
  const Pose2 odom{1.0, 2.0, 0.0};
  EXPECT_DOUBLE_EQ(1.0, decide(odom, kTruth).view);  // the first: a whole view
  const Pose2 step{0.05, 0.0, 0.0};
  EXPECT_DOUBLE_EQ(0.25, decide(compose(odom, step), kTruth).view);
  EXPECT_DOUBLE_EQ(0.0, decide(compose(odom, step), kTruth).view);  // standing still
  // Requested: a whole view, as at the default thresholds, where every
  // update brings one.
  gate_.requestUpdate();
  EXPECT_DOUBLE_EQ(1.0, decide(compose(odom, step), kTruth).view);
  params_.update_min_d = 0.2;
  params_.update_min_a = M_PI / 6;
  EXPECT_DOUBLE_EQ(1.0, decide(compose(odom, {0.3, 0.0, 0.0}), kTruth).view);
}

// While the odometry is suspect every scan updates, however little the
// odometry moved: such an update counts what the least update the
// thresholds let through brings, or its motion's share if that is more.
TEST_F(UpdateGateTest, ASuspectOdometrysUpdateCountsAtLeastWhatTheThresholdsLetThrough) {
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  // The defaults: every update is a whole view, suspect or not.
  GateDecision d = decide(odom, kTruth, true);
  ASSERT_TRUE(d.runs()) << toString(d.skip_reason);  // standing still, yet it runs
  EXPECT_DOUBLE_EQ(1.0, d.view);
  // 0.05 m or 0.1 rad: a quarter of 0.2 m, a fifth of pi/6; the least is the turn's.
  params_.update_min_d = 0.05;
  params_.update_min_a = 0.1;
  d = decide(odom, kTruth, true);
  ASSERT_TRUE(d.runs()) << toString(d.skip_reason);
  EXPECT_DOUBLE_EQ(0.1 / (M_PI / 6), d.view);
  EXPECT_DOUBLE_EQ(0.5, decide(compose(odom, {0.1, 0.0, 0.0}), kTruth, true).view);  // its motion
  // Updates on every scan: the motion's share alone.
  params_.update_min_d = params_.update_min_a = 0.0;
  EXPECT_NEAR(0.25, decide(compose(odom, {0.15, 0.0, 0.0}), kTruth, true).view, 1e-12);
  EXPECT_NEAR(0.0, decide(compose(odom, {0.15, 0.0, 0.0}), kTruth, true).view, 1e-12);
}

TEST_F(UpdateGateTest, AScanThatStopsFittingBringsAWholeView) {
  params_.update_fit_drop = 0.2;
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  gate_.recordFit(model_, {model_.prepare(castScan(grid_, kTruth))}, kTruth, params_);
  const GateDecision d = gate_.decide(compose(odom, {0.05, 0.0, 0.0}),
                                      castScan(grid_, compose(kTruth, {0.45, 0.3, 0.0})), &model_,
                                      true, kTruth, false, params_);
  ASSERT_TRUE(d.fit_dropped);
  EXPECT_DOUBLE_EQ(1.0, d.view);  // whatever the odometry says, the scan changed
}

TEST_F(UpdateGateTest, RestartMakesTheNextUpdateTheFirst) {
  const Pose2 odom{1.0, 2.0, 0.0};
  ASSERT_TRUE(decide(odom, kTruth).runs());
  gate_.restart();
  EXPECT_FALSE(gate_.hasUpdated());
  const GateDecision d = decide(odom, kTruth);
  EXPECT_TRUE(d.runs());
  EXPECT_FALSE(d.from.has_value());
}

TEST(SkipReason, EveryReasonHasItsOwnName) {
  const SkipReason all[] = {SkipReason::kNone,           SkipReason::kNoMap,
                            SkipReason::kNotInitialized, SkipReason::kOdometryNotFinite,
                            SkipReason::kBadScan,        SkipReason::kOdometryJumped,
                            SkipReason::kNotMoved,       SkipReason::kNoValidBeam};
  for (const SkipReason a : all) {
    for (const SkipReason b : all) {
      if (a != b) {
        EXPECT_STRNE(toString(a), toString(b));
      }
    }
  }
}

}  // namespace
}  // namespace pf
