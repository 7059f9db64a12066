#include "pf_localization/core/util/pose2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/expect_pose.h"

namespace pf {
namespace {

constexpr double kTol = 1e-12;

// The (-pi, pi] contract.
void expectInRange(double a) {
  EXPECT_GT(a, -M_PI);
  EXPECT_LE(a, M_PI);
}

TEST(NormalizeAngle, LeavesAnglesInsideTheRangeUntouched) {
  EXPECT_EQ(0.0, normalizeAngle(0.0));
  EXPECT_EQ(1.0, normalizeAngle(1.0));
  EXPECT_EQ(-1.0, normalizeAngle(-1.0));
  EXPECT_EQ(M_PI / 2, normalizeAngle(M_PI / 2));
  EXPECT_EQ(3.0, normalizeAngle(3.0));
  EXPECT_EQ(-3.0, normalizeAngle(-3.0));
}

TEST(NormalizeAngle, PiStaysAndMinusPiBecomesPi) {
  // The range is half open: +pi is in it, -pi is not.
  EXPECT_EQ(M_PI, normalizeAngle(M_PI));
  EXPECT_EQ(M_PI, normalizeAngle(-M_PI));
  expectInRange(normalizeAngle(std::nextafter(-M_PI, 0.0)));
  EXPECT_EQ(std::nextafter(-M_PI, 0.0), normalizeAngle(std::nextafter(-M_PI, 0.0)));
}

TEST(NormalizeAngle, WrapsMultiplesOfTwoPi) {
  EXPECT_NEAR(0.0, normalizeAngle(2 * M_PI), kTol);
  EXPECT_NEAR(0.0, normalizeAngle(-2 * M_PI), kTol);
  EXPECT_NEAR(0.0, normalizeAngle(4 * M_PI), kTol);
  EXPECT_NEAR(0.0, normalizeAngle(-10 * M_PI), 1e-11);
  EXPECT_NEAR(0.5, normalizeAngle(2 * M_PI + 0.5), kTol);
  EXPECT_NEAR(-0.5, normalizeAngle(-2 * M_PI - 0.5), kTol);
  EXPECT_NEAR(M_PI - 0.25, normalizeAngle(-M_PI - 0.25), kTol);
  EXPECT_NEAR(-M_PI + 0.25, normalizeAngle(M_PI + 0.25), kTol);
  // 100 rad = 16 turns (100.531 rad) less 0.5310 rad.
  EXPECT_NEAR(100.0 - 32 * M_PI, normalizeAngle(100.0), 1e-11);
}

TEST(NormalizeAngle, OddMultiplesOfPiLandOnPi) {
  // 3 * M_PI is not exactly 3 pi, so the result is within rounding of +pi or
  // of -pi (never below -pi): what matters is the range and the direction.
  for (int k : {3, -3, 5, -5, 7, -7, 101}) {
    const double a = normalizeAngle(k * M_PI);
    expectInRange(a);
    EXPECT_NEAR(M_PI, std::fabs(a), 1e-12) << k << " pi -> " << a;
  }
}

TEST(NormalizeAngle, StaysInRangeAndKeepsTheDirection) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-100.0, 100.0);
  for (int i = 0; i < 1000; ++i) {
    const double a = angle(rng);
    const double n = normalizeAngle(a);
    expectInRange(n);
    EXPECT_NEAR(std::cos(a), std::cos(n), 1e-12);
    EXPECT_NEAR(std::sin(a), std::sin(n), 1e-12);
  }
}

TEST(AngleDiff, TakesTheShortWayAcrossPi) {
  EXPECT_NEAR(0.2, angleDiff(0.3, 0.1), kTol);
  EXPECT_NEAR(-0.2, angleDiff(0.1, 0.3), kTol);
  // From just below +pi to just above -pi is a small positive step.
  EXPECT_NEAR(0.2, angleDiff(-M_PI + 0.1, M_PI - 0.1), kTol);
  EXPECT_NEAR(-0.2, angleDiff(M_PI - 0.1, -M_PI + 0.1), kTol);
  EXPECT_NEAR(0.0, angleDiff(M_PI, -M_PI), kTol);
  // Half a turn either way is +pi, not -pi.
  EXPECT_NEAR(M_PI, angleDiff(M_PI / 2, -M_PI / 2), kTol);
  EXPECT_NEAR(M_PI, angleDiff(-M_PI / 2, M_PI / 2), kTol);
  expectInRange(angleDiff(-M_PI / 2, M_PI / 2));
}

TEST(Pose2, ComposeRotatesTheSecondPoseIntoTheFirstFrame) {
  const Pose2 a{1.0, 2.0, M_PI / 2};
  // 3 m ahead of a robot facing +y is 3 m up in the world.
  expectPoseNear({1.0, 5.0, M_PI / 2}, compose(a, {3.0, 0.0, 0.0}));
  // 1 m to its left is 1 m in -x, and it turns a quarter more.
  expectPoseNear({0.0, 2.0, M_PI}, compose(a, {0.0, 1.0, M_PI / 2}));
  // Yaws wrap: 3pi/4 + pi/2 = 5pi/4 = -3pi/4.
  const Pose2 c = compose({0.0, 0.0, 3 * M_PI / 4}, {0.0, 0.0, M_PI / 2});
  EXPECT_NEAR(-3 * M_PI / 4, c.yaw, kTol);
}

TEST(Pose2, InverseOfAKnownPose) {
  // The world origin seen from (1, 2) facing +y: R(-pi/2) * (-1, -2) = (-2, 1),
  // 2 m behind it and 1 m to its left.
  expectPoseNear({-2.0, 1.0, -M_PI / 2}, inverse({1.0, 2.0, M_PI / 2}));
  expectPoseNear({-3.0, 0.0, 0.0}, inverse({3.0, 0.0, 0.0}));
  // Inverting a half turn gives a half turn, reported as +pi.
  const Pose2 i = inverse({1.0, 0.0, M_PI});
  expectPoseNear({1.0, 0.0, M_PI}, i);
  expectInRange(i.yaw);
}

TEST(Pose2, BetweenOfAKnownPair) {
  // b is 2 m up from a, which faces +y: 2 m straight ahead of a, turned pi/2.
  expectPoseNear({2.0, 0.0, M_PI / 2}, between({1.0, 1.0, M_PI / 2}, {1.0, 3.0, M_PI}));
}

TEST(Pose2, GroupIdentitiesHoldForRandomPoses) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> coord(-10.0, 10.0);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  auto random_pose = [&] { return Pose2{coord(rng), coord(rng), angle(rng)}; };
  const Pose2 identity{0.0, 0.0, 0.0};
  for (int i = 0; i < 200; ++i) {
    const Pose2 a = random_pose(), b = random_pose(), c = random_pose();
    expectPoseNear(identity, compose(a, inverse(a)), 1e-11);
    expectPoseNear(identity, compose(inverse(a), a), 1e-11);
    expectPoseNear(identity, between(a, a), 1e-11);
    expectPoseNear(a, compose(a, identity));
    expectPoseNear(a, compose(identity, a));
    expectPoseNear(a, inverse(inverse(a)), 1e-11);
    expectPoseNear(b, compose(a, between(a, b)), 1e-11);
    expectPoseNear(inverse(between(b, a)), between(a, b), 1e-11);
    expectPoseNear(compose(compose(a, b), c), compose(a, compose(b, c)), 1e-11);
    expectInRange(compose(a, b).yaw);
    expectInRange(inverse(a).yaw);
  }
}

TEST(Pose2, IsFinite) {
  EXPECT_TRUE((Pose2{1.0, -2.0, 3.0}).isFinite());
  EXPECT_FALSE((Pose2{NAN, 0.0, 0.0}).isFinite());
  EXPECT_FALSE((Pose2{0.0, INFINITY, 0.0}).isFinite());
  EXPECT_FALSE((Pose2{0.0, 0.0, -INFINITY}).isFinite());
}

}  // namespace
}  // namespace pf
