#include "pf_localization/core/estimate/confidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace pf {
namespace {

Confidence localized() {
  Confidence c;
  c.state = LocalizationState::kLocalized;
  c.reason = "95 % of the beams fit, one hypothesis";
  return c;
}

ConfidenceParams holdParams() {
  ConfidenceParams p;
  p.jump_distance = 0.5;
  p.jump_yaw = 0.5;
  p.settle_updates = 3;
  return p;
}

TEST(HoldAfterJump, SmallCorrectionsKeepTheVerdict) {
  int settle = 0;
  Confidence c = localized();
  // 0.4 m and 0.4 rad beyond the odometry: a correction, not a jump.
  holdAfterJump({1.0, 2.0, 0.0}, {1.4, 2.0, 0.4}, holdParams(), &settle, &c);
  EXPECT_EQ(LocalizationState::kLocalized, c.state);
  EXPECT_EQ(0, settle);
}

TEST(HoldAfterJump, AJumpIsUncertainUntilSettleUpdatesAgree) {
  const ConfidenceParams p = holdParams();
  int settle = 0;
  Confidence c = localized();
  holdAfterJump({1.0, 2.0, 0.0}, {1.0, 2.6, 0.0}, p, &settle, &c);  // 0.6 m sideways
  EXPECT_EQ(LocalizationState::kUncertain, c.state);
  EXPECT_EQ("the estimate jumped recently: 3 more updates to confirm it", c.reason);
  // Two agreeing updates still wait; the third is localized again.
  for (int left : {2, 1}) {
    c = localized();
    holdAfterJump({5.0, 5.0, 1.0}, {5.0, 5.0, 1.0}, p, &settle, &c);
    EXPECT_EQ(LocalizationState::kUncertain, c.state) << left;
    EXPECT_EQ(left, settle);
  }
  c = localized();
  holdAfterJump({5.0, 5.0, 1.0}, {5.1, 5.0, 1.0}, p, &settle, &c);
  EXPECT_EQ(LocalizationState::kLocalized, c.state);
  EXPECT_EQ(0, settle);
}

TEST(HoldAfterJump, AHalfTurnIsAJumpAndAnotherJumpRestartsTheCount) {
  const ConfidenceParams p = holdParams();
  int settle = 0;
  Confidence c = localized();
  holdAfterJump({0.0, 0.0, 3.0}, {0.0, 0.0, -3.0}, p, &settle, &c);  // 0.28 rad across pi: none
  EXPECT_EQ(0, settle);
  holdAfterJump({0.0, 0.0, 0.0}, {0.0, 0.0, M_PI}, p, &settle, &c);
  EXPECT_EQ(3, settle);
  holdAfterJump({0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, p, &settle, &c);
  EXPECT_EQ(2, settle);
  holdAfterJump({0.0, 0.0, 0.0}, {-3.0, 0.0, 0.0}, p, &settle, &c);
  EXPECT_EQ(3, settle);
}

TEST(HoldAfterJump, LeavesLostAndUncertainVerdictsAlone) {
  int settle = 0;
  Confidence c;
  c.state = LocalizationState::kLost;
  c.reason = "only 30 % of the beams fit the map at the estimate";
  holdAfterJump({0.0, 0.0, 0.0}, {9.0, 0.0, 0.0}, holdParams(), &settle, &c);
  EXPECT_EQ(LocalizationState::kLost, c.state);
  EXPECT_EQ("only 30 % of the beams fit the map at the estimate", c.reason);
  EXPECT_EQ(3, settle);
}

TEST(HoldAfterJump, ZeroSettleUpdatesNeverHolds) {
  ConfidenceParams p = holdParams();
  p.settle_updates = 0;
  int settle = 0;
  Confidence c = localized();
  holdAfterJump({0.0, 0.0, 0.0}, {9.0, 0.0, 0.0}, p, &settle, &c);
  EXPECT_EQ(LocalizationState::kLocalized, c.state);
}

TEST(ConfidenceParams, InvalidJumpParametersAreNamed) {
  ConfidenceParams p;
  p.jump_distance = 0.0;
  EXPECT_THROW(validate(p), std::invalid_argument);
  p = ConfidenceParams();
  p.settle_updates = -1;
  try {
    validate(p);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ("invalid parameter confidence_settle_updates = -1: must be >= 0", e.what());
  }
}

}  // namespace
}  // namespace pf
