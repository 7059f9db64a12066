#include "pf_localization/core/motion/odometry_motion_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/expect_pose.h"
#include "pf_localization/core/filter/view_share.h"

namespace pf {
namespace {

constexpr double kTol = 1e-12;

// A moved particle: the pose, and a yaw kept in (-pi, pi].
void expectMovedTo(const Pose2& expected, const Pose2& actual, double tol = kTol) {
  expectPoseNear(expected, actual, tol);
  EXPECT_GT(actual.yaw, -M_PI);
  EXPECT_LE(actual.yaw, M_PI);
}

void expectStep(const OdometryStep& expected, const OdometryStep& actual) {
  EXPECT_NEAR(expected.rot1, actual.rot1, kTol);
  EXPECT_NEAR(expected.trans, actual.trans, kTol);
  EXPECT_NEAR(expected.rot2, actual.rot2, kTol);
}

OdometryMotionParams noiseless(OdometryMotionParams::Kind kind) {
  OdometryMotionParams p;
  p.kind = kind;
  p.alpha1 = p.alpha2 = p.alpha3 = p.alpha4 = p.alpha5 = 0.0;
  return p;
}

ParticleSet particlesAt(const std::vector<Pose2>& poses) {
  ParticleSet set;
  set.resize(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) set.setPose(i, poses[i]);
  set.setUniformWeights();
  return set;
}

ParticleSet manyAt(const Pose2& pose, std::size_t n) {
  return particlesAt(std::vector<Pose2>(n, pose));
}

struct Stats {
  double mean;
  double stddev;
};

template <typename F>
Stats stats(std::size_t n, F value) {
  double sum = 0.0, sum_sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += value(i);
  const double mean = sum / n;
  for (std::size_t i = 0; i < n; ++i) sum_sq += (value(i) - mean) * (value(i) - mean);
  return {mean, std::sqrt(sum_sq / n)};
}

// --- decompose ---------------------------------------------------------------

TEST(Decompose, StraightAhead) {
  expectStep({0.0, 1.0, 0.0}, OdometryMotionModel::decompose({0, 0, 0}, {1, 0, 0}));
  // Facing +y and moving +y is still straight ahead.
  expectStep({0.0, 2.0, 0.0}, OdometryMotionModel::decompose({1, 1, M_PI / 2}, {1, 3, M_PI / 2}));
}

TEST(Decompose, TurnMoveTurn) {
  // To (1, 1) facing +y: turn pi/4 towards it, go sqrt(2), turn the other pi/4.
  expectStep({M_PI / 4, std::sqrt(2.0), M_PI / 4},
             OdometryMotionModel::decompose({0, 0, 0}, {1, 1, M_PI / 2}));
  // Sideways to the right, ending with the original heading.
  expectStep({-M_PI / 2, 0.5, M_PI / 2}, OdometryMotionModel::decompose({0, 0, 0}, {0, -0.5, 0}));
}

TEST(Decompose, BackwardsIsAHalfTurnEachWay) {
  // Reversing 1 m: the direction of travel is behind, so rot1 = pi, and the
  // heading is unchanged, so rot2 = -pi, reported as +pi.
  const OdometryStep back = OdometryMotionModel::decompose({0, 0, 0}, {-1, 0, 0});
  EXPECT_EQ(M_PI, back.rot1);
  EXPECT_EQ(1.0, back.trans);
  EXPECT_EQ(M_PI, back.rot2);
  // Facing +y and reversing 0.5 m towards -y.
  expectStep({M_PI, 0.5, M_PI},
             OdometryMotionModel::decompose({2, 1, M_PI / 2}, {2, 0.5, M_PI / 2}));
  // Reversing 1 m along an arc that turns 0.2 rad left: the chord points
  // atan2(-sin(0.1), -cos(0.1)) = -pi + 0.1, and rot2 = 0.2 - (-pi + 0.1)
  // = pi + 0.1, which wraps to -pi + 0.1.
  const OdometryStep turning =
      OdometryMotionModel::decompose({0, 0, 0}, {-std::cos(0.1), -std::sin(0.1), 0.2});
  expectStep({-M_PI + 0.1, 1.0, -M_PI + 0.1}, turning);
}

TEST(Decompose, RotationAcrossPi) {
  // In place, from just below +pi to just above -pi: a 0.2 rad left turn.
  expectStep({0.0, 0.0, 0.2},
             OdometryMotionModel::decompose({0, 0, M_PI - 0.1}, {0, 0, -M_PI + 0.1}));
  // Moving 1 m along -x while facing pi - 0.1 and ending at -pi + 0.1:
  // rot1 = pi - (pi - 0.1) = 0.1, rot2 = 0.2 - 0.1 = 0.1.
  expectStep({0.1, 1.0, 0.1},
             OdometryMotionModel::decompose({0, 0, M_PI - 0.1}, {-1, 0, -M_PI + 0.1}));
}

TEST(Decompose, TinyTranslationHasNoDirection) {
  // Below 1 cm the direction of travel is noise: all rotation goes to rot2.
  expectStep({0.0, std::hypot(0.005, 0.005), 1.0},
             OdometryMotionModel::decompose({0, 0, 0}, {0.005, 0.005, 1.0}));
  expectStep({0.0, 0.0, 0.0}, OdometryMotionModel::decompose({3, 4, 1}, {3, 4, 1}));
}

// --- apply without noise -----------------------------------------------------

TEST(ApplyNoiseless, ForwardMovesEveryParticleAlongItsHeading) {
  const OdometryMotionModel model(noiseless(OdometryMotionParams::Kind::kDifferential));
  ParticleSet p = particlesAt({{0, 0, 0}, {1, 1, M_PI / 2}, {-2, 3, M_PI}, {0.5, -0.5, -M_PI / 2}});
  Random random(1);
  // The odometry frame differs from the map frame: only the relative motion
  // (1 m forward) matters.
  model.apply({10, 10, 0}, {11, 10, 0}, &p, &random);
  expectMovedTo({1, 0, 0}, p.pose(0));
  expectMovedTo({1, 2, M_PI / 2}, p.pose(1));
  expectMovedTo({-3, 3, M_PI}, p.pose(2));
  expectMovedTo({0.5, -1.5, -M_PI / 2}, p.pose(3));
  // Weights are not the motion model's business.
  for (double w : p.weight) EXPECT_EQ(0.25, w);
}

TEST(ApplyNoiseless, BackwardMovesEveryParticleBackwards) {
  const OdometryMotionModel model(noiseless(OdometryMotionParams::Kind::kDifferential));
  ParticleSet p = particlesAt({{0, 0, 0}, {1, 1, M_PI / 2}, {-2, 3, M_PI}});
  Random random(1);
  model.apply({0, 0, 0}, {-1, 0, 0}, &p, &random);
  expectMovedTo({-1, 0, 0}, p.pose(0));
  expectMovedTo({1, 0, M_PI / 2}, p.pose(1));
  expectMovedTo({-1, 3, M_PI}, p.pose(2));
}

TEST(ApplyNoiseless, PureRotationAcrossPi) {
  const OdometryMotionModel model(noiseless(OdometryMotionParams::Kind::kDifferential));
  ParticleSet p = particlesAt({{1, 2, M_PI - 0.05}, {-1, 0, 0}});
  Random random(1);
  model.apply({5, 5, M_PI - 0.1}, {5, 5, -M_PI + 0.1}, &p, &random);
  // +0.2 rad: pi - 0.05 + 0.2 wraps to -pi + 0.15. Positions do not move.
  EXPECT_EQ(1.0, p.x[0]);
  EXPECT_EQ(2.0, p.y[0]);
  EXPECT_NEAR(-M_PI + 0.15, p.yaw[0], kTol);
  EXPECT_EQ(-1.0, p.x[1]);
  EXPECT_EQ(0.0, p.y[1]);
  EXPECT_NEAR(0.2, p.yaw[1], kTol);
}

TEST(ApplyNoiseless, EqualsComposingTheOdometryDelta) {
  // Without noise a particle p moves to p (+) (from^-1 (+) to), for any motion
  // of at least 1 cm, forwards, backwards or sideways, in either model.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-5.0, 5.0), angle(-M_PI, M_PI), step(-1.0, 1.0);
  for (auto kind : {OdometryMotionParams::Kind::kDifferential, OdometryMotionParams::Kind::kOmni}) {
    const OdometryMotionModel model(noiseless(kind));
    Random random(1);
    for (int trial = 0; trial < 100; ++trial) {
      const Pose2 from{coord(rng), coord(rng), angle(rng)};
      Pose2 delta{step(rng), step(rng), angle(rng)};
      if (std::hypot(delta.x, delta.y) < 0.02) delta.x = 0.5;
      const Pose2 to = compose(from, delta);
      const Pose2 start{coord(rng), coord(rng), angle(rng)};
      ParticleSet p = particlesAt({start});
      model.apply(from, to, &p, &random);
      expectMovedTo(compose(start, delta), p.pose(0), 1e-9);
    }
  }
}

TEST(ApplyNoiseless, OmniMovesSideways) {
  const OdometryMotionModel model(noiseless(OdometryMotionParams::Kind::kOmni));
  ParticleSet p = particlesAt({{1, 1, M_PI / 2}, {0, 0, 0}});
  Random random(1);
  // 1 m to the robot's left without turning: for a particle facing +y that is
  // 1 m towards -x.
  model.apply({0, 0, 0}, {0, 1, 0}, &p, &random);
  expectMovedTo({0, 1, M_PI / 2}, p.pose(0));
  expectMovedTo({0, 1, 0}, p.pose(1));
  // Diagonally while turning a quarter: (1, 1) in the robot frame.
  model.apply({0, 0, 0}, {1, 1, M_PI / 2}, &p, &random);
  expectMovedTo({-1, 2, M_PI}, p.pose(0));
  expectMovedTo({1, 2, M_PI / 2}, p.pose(1));
  // In-place rotation across pi.
  model.apply({0, 0, M_PI - 0.1}, {0, 0, -M_PI + 0.1}, &p, &random);
  expectMovedTo({-1, 2, -M_PI + 0.2}, p.pose(0));
}

// --- apply with noise ---------------------------------------------------------

constexpr std::size_t kSamples = 40000;

OdometryMotionParams noisy() {
  OdometryMotionParams p;
  p.alpha1 = 0.1;          // rot from rot
  p.alpha2 = 0.01;         // rot from trans
  p.alpha3 = 0.04;         // trans from trans
  p.alpha4 = 0.02;         // trans from rot
  p.alpha5 = 0.09;         // strafe (omni)
  p.fault_fraction = 0.0;  // the textbook model; the fault mixture has its own tests
  return p;
}

TEST(ApplyNoisy, ForwardSpreadMatchesTheModel) {
  const OdometryMotionModel model(noisy());
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(11);
  model.apply({0, 0, 0}, {1, 0, 0}, &p, &random);
  // rot1 = rot2 = 0, trans = 1:
  //   sigma_rot1 = sigma_rot2 = sqrt(alpha2 * 1) = 0.1, sigma_trans = sqrt(alpha3) = 0.2.
  // The travelled distance and its direction recover trans and rot1; the
  // final heading less that direction recovers rot2.
  const Stats trans = stats(kSamples, [&](std::size_t i) { return std::hypot(p.x[i], p.y[i]); });
  const Stats rot1 = stats(kSamples, [&](std::size_t i) { return std::atan2(p.y[i], p.x[i]); });
  const Stats rot2 = stats(
      kSamples, [&](std::size_t i) { return angleDiff(p.yaw[i], std::atan2(p.y[i], p.x[i])); });
  EXPECT_NEAR(1.0, trans.mean, 0.005);
  EXPECT_NEAR(0.2, trans.stddev, 0.01);
  EXPECT_NEAR(0.0, rot1.mean, 0.003);
  EXPECT_NEAR(0.1, rot1.stddev, 0.005);
  EXPECT_NEAR(0.0, rot2.mean, 0.003);
  EXPECT_NEAR(0.1, rot2.stddev, 0.005);
  // The final heading: the sum of both, sqrt(0.01 + 0.01).
  const Stats yaw = stats(kSamples, [&](std::size_t i) { return p.yaw[i]; });
  EXPECT_NEAR(0.0, yaw.mean, 0.003);
  EXPECT_NEAR(std::sqrt(0.02), yaw.stddev, 0.007);
}

TEST(ApplyNoisy, RotationInPlaceSpreadMatchesTheModel) {
  const OdometryMotionModel model(noisy());
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(12);
  model.apply({0, 0, 0}, {0, 0, 1.0}, &p, &random);
  // rot1 = 0, trans = 0, rot2 = 1: sigma_rot1 = 0, so every particle slides
  // along its unchanged heading (+x) by the translation noise
  // sqrt(alpha4 * 1) = 0.141, and turns by 1 with sqrt(alpha1 * 1) = 0.316.
  for (std::size_t i = 0; i < kSamples; ++i) ASSERT_EQ(0.0, p.y[i]);
  const Stats x = stats(kSamples, [&](std::size_t i) { return p.x[i]; });
  const Stats yaw = stats(kSamples, [&](std::size_t i) { return p.yaw[i]; });
  EXPECT_NEAR(0.0, x.mean, 0.003);
  EXPECT_NEAR(std::sqrt(0.02), x.stddev, 0.007);
  EXPECT_NEAR(1.0, yaw.mean, 0.006);
  EXPECT_NEAR(std::sqrt(0.1), yaw.stddev, 0.016);
}

TEST(ApplyNoisy, DrivingBackwardsIsNotTurningAround) {
  const OdometryMotionModel model(noisy());
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(13);
  model.apply({0, 0, 0}, {-1, 0, 0}, &p, &random);
  // rot1 = rot2 = pi would give the textbook model a rotation noise of
  // sqrt(alpha1 pi^2 + alpha2) = 1.0 rad and a translation noise of
  // sqrt(alpha3 + alpha4 2 pi^2) = 0.89 m. Reversing 1 m is really a 1 m
  // move: the same 0.1 rad, 0.2 m and 0.1 rad as forwards.
  const Stats trans = stats(kSamples, [&](std::size_t i) { return std::hypot(p.x[i], p.y[i]); });
  const Stats rot1 = stats(kSamples, [&](std::size_t i) {
    return angleDiff(std::atan2(p.y[i], p.x[i]), M_PI);  // deviation from straight back
  });
  const Stats yaw = stats(kSamples, [&](std::size_t i) { return p.yaw[i]; });
  EXPECT_NEAR(1.0, trans.mean, 0.005);
  EXPECT_NEAR(0.2, trans.stddev, 0.01);
  EXPECT_NEAR(0.0, rot1.mean, 0.003);
  EXPECT_NEAR(0.1, rot1.stddev, 0.005);
  EXPECT_NEAR(0.0, yaw.mean, 0.003);
  EXPECT_NEAR(std::sqrt(0.02), yaw.stddev, 0.007);
  const Stats x = stats(kSamples, [&](std::size_t i) { return p.x[i]; });
  EXPECT_NEAR(-1.0, x.mean, 0.01);
}

TEST(ApplyNoisy, OmniSpreadMatchesTheModel) {
  OdometryMotionParams params = noisy();
  params.kind = OdometryMotionParams::Kind::kOmni;
  const OdometryMotionModel model(params);
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(14);
  model.apply({0, 0, 0}, {1, 0, 0}, &p, &random);
  // trans = 1, rot = 0: forward sqrt(alpha3) = 0.2, strafe sqrt(alpha5) = 0.3,
  // heading sqrt(alpha2) = 0.1.
  const Stats x = stats(kSamples, [&](std::size_t i) { return p.x[i]; });
  const Stats y = stats(kSamples, [&](std::size_t i) { return p.y[i]; });
  const Stats yaw = stats(kSamples, [&](std::size_t i) { return p.yaw[i]; });
  EXPECT_NEAR(1.0, x.mean, 0.005);
  EXPECT_NEAR(0.2, x.stddev, 0.01);
  EXPECT_NEAR(0.0, y.mean, 0.008);
  EXPECT_NEAR(0.3, y.stddev, 0.015);
  EXPECT_NEAR(0.0, yaw.mean, 0.003);
  EXPECT_NEAR(0.1, yaw.stddev, 0.005);
}

// --- a step longer than one update's -----------------------------------------

TEST(ApplyLongStep, ItsNoiseAddsUpLikeThatOfTheUpdatesItSpans) {
  // amcl's alphas, a 2 m step (a scan 2.5 s after the last at 0.8 m/s) and
  // one update's step 0.4 m: five updates' noise, variance alpha * 2 * 0.4.
  OdometryMotionParams params;
  params.fault_fraction = 0.0;
  const OdometryMotionModel model(params, {0.4, M_PI / 3});
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(15);
  model.apply({0, 0, 0}, {2, 0, 0}, &p, &random);
  const Stats trans = stats(kSamples, [&](std::size_t i) { return std::hypot(p.x[i], p.y[i]); });
  const Stats rot1 = stats(kSamples, [&](std::size_t i) { return std::atan2(p.y[i], p.x[i]); });
  EXPECT_NEAR(std::sqrt(0.2 * 2.0 * 0.4), trans.stddev, 0.01);  // 0.4 m, not 0.89
  EXPECT_NEAR(std::sqrt(0.2 * 2.0 * 0.4), rot1.stddev, 0.01);   // 0.4 rad, not 0.89
  // So the particles go nearly as far as the odometry: the direction's
  // noise costs cos of it, exp(-0.16 / 2) = 0.92 on average, where a
  // quadratic 0.89 rad left them at exp(-0.8 / 2) = 0.67 of the way.
  const Stats x = stats(kSamples, [&](std::size_t i) { return p.x[i]; });
  EXPECT_NEAR(2.0 * std::exp(-0.08), x.mean, 0.01);

  // Turning 1.5 rad in place: 1.5 / (pi / 3) updates' turning.
  ParticleSet q = manyAt({0, 0, 0}, kSamples);
  model.apply({0, 0, 0}, {0, 0, 1.5}, &q, &random);
  const Stats yaw = stats(kSamples, [&](std::size_t i) { return angleDiff(q.yaw[i], 1.5); });
  const Stats slide = stats(kSamples, [&](std::size_t i) { return q.x[i]; });
  EXPECT_NEAR(0.0, yaw.mean, 0.01);
  EXPECT_NEAR(std::sqrt(0.2 * 1.5 * M_PI / 3), yaw.stddev, 0.01);    // 0.56 rad, not 0.67
  EXPECT_NEAR(std::sqrt(0.2 * 1.5 * M_PI / 3), slide.stddev, 0.01);  // alpha4: the same here
}

TEST(ApplyLongStep, StepsUpToOneUpdatesAreTheTextbooksDrawForDraw) {
  OdometryMotionParams params;
  params.fault_fraction = 0.03;
  const OdometryMotionModel textbook(params), spanned(params, {0.4, M_PI / 3});
  for (const Pose2& to :
       {Pose2{0.4, 0.0, 0.2}, Pose2{-0.3, 0.1, -1.0}, Pose2{0.0, 0.0, M_PI / 3}}) {
    ParticleSet a = manyAt({1, 2, 3}, 1000), b = a;
    Random ra(16), rb(16);
    textbook.apply({0, 0, 0}, to, &a, &ra);
    spanned.apply({0, 0, 0}, to, &b, &rb);
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
    EXPECT_EQ(a.yaw, b.yaw);
  }
}

TEST(ApplyLongStep, OmniToo) {
  OdometryMotionParams params = noisy();
  params.kind = OdometryMotionParams::Kind::kOmni;
  const OdometryMotionModel model(params, {0.5, M_PI / 3});
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(17);
  model.apply({0, 0, 0}, {2, 0, 0}, &p, &random);
  // Forward sqrt(alpha3 * 2 * 0.5) = 0.2, strafe sqrt(alpha5 * 1) = 0.3.
  EXPECT_NEAR(0.2, stats(kSamples, [&](std::size_t i) { return p.x[i]; }).stddev, 0.01);
  EXPECT_NEAR(0.3, stats(kSamples, [&](std::size_t i) { return p.y[i]; }).stddev, 0.015);
}

TEST(ApplyLongStep, RefusesAStepThatIsNotPositive) {
  EXPECT_THROW(OdometryMotionModel(OdometryMotionParams{}, {0.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(OdometryMotionModel(OdometryMotionParams{}, {1.0, -1.0}), std::invalid_argument);
}

// Updates closer together than a view (view_share.h): five updates of a fifth
// of a view each spread the particles as one update a view apart does;
// with the textbook's squares they spread them by a fifth of its variance.
TEST(ApplyPartialView, FiveFifthsOfAViewAddUpToOneWholeUpdatesNoise) {
  OdometryMotionParams params;  // amcl's alphas, 0.2
  params.fault_fraction = 0.0;
  const OdometryMotionModel model(params, {0.4, M_PI / 3});  // one update's step, at the defaults
  Random random(31);
  ParticleSet whole = manyAt({0, 0, 0}, kSamples);
  model.apply({0, 0, 0}, {kViewDistance, 0, 0}, 0.0, &whole, &random, nullptr);
  ParticleSet fifths = manyAt({0, 0, 0}, kSamples);
  ParticleSet textbook = manyAt({0, 0, 0}, kSamples);
  for (int k = 0; k < 5; ++k) {
    const Pose2 from{0.04 * k, 0, 0}, to{0.04 * (k + 1), 0, 0};
    model.apply(from, to, 0.0, &fifths, &random, nullptr, 1, newViewShare(between(from, to)));
    model.apply(from, to, 0.0, &textbook, &random, nullptr);
  }
  const auto x = [](const ParticleSet& p) {
    return stats(kSamples, [&](std::size_t i) { return p.x[i]; });
  };
  const auto yaw = [](const ParticleSet& p) {
    return stats(kSamples, [&](std::size_t i) { return p.yaw[i]; });
  };
  // sigma_trans^2 = alpha3 * 0.2^2 for the whole step, 5 * alpha3 * 0.04 * 0.2 in fifths.
  EXPECT_NEAR(std::sqrt(0.2 * 0.04), x(whole).stddev, 0.002);
  EXPECT_NEAR(x(whole).stddev, x(fifths).stddev, 0.003);
  EXPECT_NEAR(yaw(whole).stddev, yaw(fifths).stddev, 0.003);
  EXPECT_NEAR(std::sqrt(0.2 * 0.04 / 5), x(textbook).stddev, 0.002);
}

// A model whose only noise is the fault mixture: a share `fraction` of the
// particles reverses or stalls within +-`margin`.
OdometryMotionModel faultsOnly(double fraction, double margin) {
  OdometryMotionParams params;
  params.alpha1 = params.alpha2 = params.alpha3 = params.alpha4 = 0.0;
  params.fault_fraction = fraction;
  params.fault_margin = margin;
  return OdometryMotionModel(params);
}

TEST(ApplyPartialView, AStalledRobotsSpreadIsItsShareOfTheMargin) {
  const OdometryMotionModel model = faultsOnly(0.5, 0.1);
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(32);
  model.apply({0, 0, 0}, {0.1, 0, 0}, 0.5, &p, &random, nullptr, 1, 0.5);
  double widest = 0.0;
  for (std::size_t i = 0; i < kSamples; ++i) {
    if (std::fabs(p.x[i]) < 0.09) widest = std::max(widest, std::fabs(p.x[i]));  // the stalled
  }
  EXPECT_LE(widest, 0.05);  // half of fault_margin for half a view
  EXPECT_GT(widest, 0.049);
}

// The fault mixture: with noise-free alphas, a particle either moves exactly
// by the odometry, or (the faulty share) exactly the reverse, or stalls
// within +-fault_margin, in equal halves of the faulty share.
TEST(ApplyFaults, AShareOfTheParticlesReversesOrStalls) {
  const OdometryMotionModel model = faultsOnly(0.25, 0.1);
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(21);
  model.apply({0, 0, 0}, {1, 0, 0}, &p, &random);
  std::size_t forward = 0, reversed = 0, stalled = 0;
  double stalled_sum = 0.0, stalled_sq = 0.0;
  for (std::size_t i = 0; i < kSamples; ++i) {
    ASSERT_EQ(0.0, p.y[i]);  // the heading is exact: only the translation is in doubt
    ASSERT_EQ(0.0, p.yaw[i]);
    if (p.x[i] == 1.0) {
      ++forward;
    } else if (p.x[i] == -1.0) {
      ++reversed;
    } else {
      ASSERT_LE(std::fabs(p.x[i]), 0.1) << i;
      ++stalled;
      stalled_sum += p.x[i];
      stalled_sq += p.x[i] * p.x[i];
    }
  }
  // 75 %, 12.5 % and 12.5 % of 40000; binomial std 87, 66, 66.
  EXPECT_NEAR(30000.0, static_cast<double>(forward), 350.0);
  EXPECT_NEAR(5000.0, static_cast<double>(reversed), 270.0);
  EXPECT_NEAR(5000.0, static_cast<double>(stalled), 270.0);
  const double n = static_cast<double>(stalled);
  EXPECT_NEAR(0.0, stalled_sum / n, 0.003);
  EXPECT_NEAR(0.2 / std::sqrt(12.0), std::sqrt(stalled_sq / n), 0.002);  // uniform on +-0.1
}

TEST(ApplyFaults, ReversedParticlesKeepTheTranslationNoise) {
  OdometryMotionParams params = noisy();  // sigma_trans = sqrt(alpha3) = 0.2 for 1 m
  params.fault_fraction = 0.5;
  params.fault_margin = 0.0;
  const OdometryMotionModel model(params);
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(22);
  model.apply({0, 0, 0}, {1, 0, 0}, &p, &random);
  std::vector<double> back;  // the reversed quarter: along -x
  for (std::size_t i = 0; i < kSamples; ++i) {
    if (p.x[i] < -0.3) back.push_back(-std::hypot(p.x[i], p.y[i]));
  }
  EXPECT_NEAR(10000.0, static_cast<double>(back.size()), 350.0);
  const Stats b = stats(back.size(), [&](std::size_t i) { return back[i]; });
  EXPECT_NEAR(-1.0, b.mean, 0.01);
  EXPECT_NEAR(0.2, b.stddev, 0.01);
}

TEST(ApplyFaults, AnExplicitShareOverridesTheParameterAndFlagsTheFaultyParticles) {
  OdometryMotionParams params;
  params.alpha1 = params.alpha2 = params.alpha3 = params.alpha4 = 0.0;
  params.fault_fraction = 0.0;  // the call's 0.4 applies
  const OdometryMotionModel model(params);
  ParticleSet p = manyAt({0, 0, 0}, kSamples);
  Random random(23);
  std::vector<uint8_t> faulty;
  model.apply({0, 0, 0}, {1, 0, 0}, 0.4, &p, &random, &faulty);
  ASSERT_EQ(kSamples, faulty.size());
  std::size_t flagged = 0;
  for (std::size_t i = 0; i < kSamples; ++i) {
    // A flagged particle reversed or stalled; the others moved exactly 1 m.
    EXPECT_EQ(faulty[i] != 0, p.x[i] != 1.0) << i;
    flagged += faulty[i];
  }
  EXPECT_NEAR(16000.0, static_cast<double>(flagged), 400.0);  // 40 %, binomial std 98
}

TEST(ApplyFaults, RefusesAFractionOfOne) {
  OdometryMotionParams params;
  params.fault_fraction = 1.0;
  EXPECT_THROW(OdometryMotionModel{params}, std::invalid_argument);
  params.fault_fraction = 0.1;
  params.fault_margin = -0.1;
  EXPECT_THROW(OdometryMotionModel{params}, std::invalid_argument);
}

TEST(ApplyNoisy, SameSeedSameParticles) {
  const OdometryMotionModel model(noisy());
  ParticleSet a = manyAt({1, 2, 3}, 100), b = a;
  Random ra(5), rb(5);
  model.apply({0, 0, 0}, {0.3, 0.1, 0.4}, &a, &ra);
  model.apply({0, 0, 0}, {0.3, 0.1, 0.4}, &b, &rb);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.yaw, b.yaw);
}

// --- parameters ---------------------------------------------------------------

TEST(OdometryMotionModel, RejectsNegativeOrNonFiniteAlphas) {
  const double bad[] = {-0.1, std::numeric_limits<double>::quiet_NaN(),
                        std::numeric_limits<double>::infinity()};
  for (int i = 0; i < 5; ++i) {
    for (double value : bad) {
      OdometryMotionParams params;
      double* alphas[] = {&params.alpha1, &params.alpha2, &params.alpha3, &params.alpha4,
                          &params.alpha5};
      *alphas[i] = value;
      const std::string name = "odom_alpha" + std::to_string(i + 1);
      try {
        OdometryMotionModel model(params);
        ADD_FAILURE() << name << " = " << value << " accepted";
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string::npos, std::string(e.what()).find(name)) << e.what();
      }
    }
  }
  EXPECT_NO_THROW(OdometryMotionModel(noiseless(OdometryMotionParams::Kind::kDifferential)));
}

}  // namespace
}  // namespace pf
