#include "pf_localization/core/estimate/cluster_estimate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/expect_pose.h"
#include "pf_localization/core/util/bin_table.h"

namespace pf {
namespace {

constexpr double kTol = 1e-12;

struct Weighted {
  Pose2 pose;
  double weight;
};

ParticleSet particles(const std::vector<Weighted>& list) {
  ParticleSet set;
  set.resize(list.size());
  for (std::size_t i = 0; i < list.size(); ++i) {
    set.setPose(i, list[i].pose);
    set.weight[i] = list[i].weight;
  }
  return set;
}

// estimatePose computes mean directions in single precision (1e-7 rad).
void expectEstimateNear(const Pose2& expected, const Pose2& actual, double tol = kTol) {
  expectPoseNear(expected, actual, tol, std::max(tol, 2e-7));
}

void expectMatrixNear(const Eigen::Matrix3d& expected, const Eigen::Matrix3d& actual,
                      double tol = kTol) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(expected(r, c), actual(r, c), tol) << r << "," << c;
  }
}

const ClusterParams kParams{0.5, 0.5236};

TEST(EstimatePose, HeavierClusterWinsEvenWithFewerParticles) {
  // A: two particles near (0.2, 0.15) carrying 0.7; B: four near (5.15, 5.15)
  // carrying 0.3.
  const ParticleSet set = particles({
      {{5.1, 5.1, 1.0}, 0.075},
      {{0.1, 0.1, 0.0}, 0.35},
      {{5.2, 5.1, 1.0}, 0.075},
      {{5.1, 5.2, 1.0}, 0.075},
      {{0.3, 0.2, 0.2}, 0.35},
      {{5.2, 5.2, 1.0}, 0.075},
  });
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(2u, e.clusters.size());
  // Sorted heaviest first.
  EXPECT_NEAR(0.7, e.clusters[0].weight, kTol);
  EXPECT_EQ(2u, e.clusters[0].count);
  EXPECT_NEAR(0.3, e.clusters[1].weight, kTol);
  EXPECT_EQ(4u, e.clusters[1].count);
  // A's mean: x = (0.1 + 0.3) / 2, y = (0.1 + 0.2) / 2, yaw halfway between 0 and 0.2.
  expectEstimateNear({0.2, 0.15, 0.1}, e.pose);
  expectEstimateNear({0.2, 0.15, 0.1}, e.clusters[0].mean);
  expectEstimateNear({5.15, 5.15, 1.0}, e.clusters[1].mean);
  // A's covariance: the deviations are +-(0.1, 0.05, 0.1), so it is d d^T.
  Eigen::Matrix3d expected;
  expected << 0.01, 0.005, 0.01,  //
      0.005, 0.0025, 0.005,       //
      0.01, 0.005, 0.01;
  expectMatrixNear(expected, e.covariance);
  expectMatrixNear(expected, e.clusters[0].covariance);
  // Not a mean of everything, which would land between the clusters.
  EXPECT_LT(e.pose.x, 1.0);
}

TEST(EstimatePose, EqualWeightClustersAreOrderedByPosition) {
  const ParticleSet set = particles({{{3.0, 0.0, 0.0}, 0.5}, {{-3.0, 0.0, 0.0}, 0.5}});
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(2u, e.clusters.size());
  EXPECT_EQ(-3.0, e.pose.x);
  EXPECT_EQ(3.0, e.clusters[1].mean.x);
}

TEST(EstimatePose, CircularMeanAcrossPiIsPi) {
  // An arithmetic mean of pi - 0.1 and -pi + 0.1 would be 0, facing the
  // other way.
  const ParticleSet set = particles({{{1, 1, M_PI - 0.1}, 0.5}, {{1, 1, -M_PI + 0.1}, 0.5}});
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(1u, e.clusters.size());
  EXPECT_NEAR(M_PI, std::fabs(e.pose.yaw), kTol);
  EXPECT_NEAR(0.0, angleDiff(e.pose.yaw, M_PI), kTol);
  // The yaw variance uses deviations from that mean (+-0.1), not from 0.
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected(2, 2) = 0.01;
  expectMatrixNear(expected, e.covariance);
}

TEST(EstimatePose, UnequalWeightsCovariance) {
  // Weights 0.5, 0.25, 0.25 at (0, 0), (0.4, 0), (0, 0.4): mean (0.1, 0.1).
  // x deviations -0.1, 0.3, -0.1: var = 0.5 * 0.01 + 0.25 * 0.09 + 0.25 * 0.01 = 0.03.
  // y likewise 0.03; cov(x, y) = 0.5 * 0.01 + 0.25 * (0.3 * -0.1) * 2 = -0.01.
  const ParticleSet set = particles({
      {{0.0, 0.0, 0.0}, 0.5},
      {{0.4, 0.0, 0.0}, 0.25},
      {{0.0, 0.4, 0.0}, 0.25},
  });
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(1u, e.clusters.size());
  expectEstimateNear({0.1, 0.1, 0.0}, e.pose);
  Eigen::Matrix3d expected;
  expected << 0.03, -0.01, 0.0,  //
      -0.01, 0.03, 0.0,          //
      0.0, 0.0, 0.0;
  expectMatrixNear(expected, e.covariance);
}

TEST(EstimatePose, ClusterStraddlingPiStaysOne) {
  // Yaw bins of 30 degrees: pi - 0.05 is in the last bin, -pi + 0.05 in the
  // first; they touch because yaw wraps.
  const ParticleSet set = particles({
      {{2.0, 2.0, M_PI - 0.05}, 0.25},
      {{2.0, 2.0, -M_PI + 0.05}, 0.25},
      {{2.0, 2.0, M_PI - 0.2}, 0.25},
      {{2.0, 2.0, -M_PI + 0.2}, 0.25},
  });
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(1u, e.clusters.size());
  EXPECT_EQ(4u, e.clusters[0].count);
  expectEstimateNear({2.0, 2.0, M_PI}, e.pose);
  // Deviations +-0.05 and +-0.2: (2 * 0.0025 + 2 * 0.04) / 4.
  EXPECT_NEAR(0.02125, e.covariance(2, 2), kTol);
}

TEST(EstimatePose, ClusterStraddlingABinEdgeInSpaceStaysOne) {
  const ParticleSet set = particles({{{-0.05, 0.0, 0.0}, 0.5}, {{0.05, -0.05, 0.0}, 0.5}});
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(1u, e.clusters.size());
  expectEstimateNear({0.0, -0.025, 0.0}, e.pose);
}

TEST(EstimatePose, OppositeHeadingsAtOnePlaceAreTwoClusters) {
  const ParticleSet set = particles({{{1.0, 1.0, 0.0}, 0.6}, {{1.0, 1.0, M_PI}, 0.4}});
  const PoseEstimate e = estimatePose(set, kParams);
  ASSERT_EQ(2u, e.clusters.size());
  expectEstimateNear({1.0, 1.0, 0.0}, e.pose);
  expectEstimateNear({1.0, 1.0, M_PI}, e.clusters[1].mean);
}

TEST(EstimatePose, ChainOfTouchingBinsIsOneCluster) {
  // Particles 0.4 m apart in a line touch bin to bin: one cluster even though
  // its ends are 2 m apart.
  std::vector<Weighted> list;
  for (int i = 0; i < 6; ++i) list.push_back({{0.4 * i, 0.0, 0.0}, 1.0 / 6});
  // A separate one 1.5 m beyond the end: bins 4 and 7 do not touch.
  list.push_back({{3.5, 0.0, 0.0}, 0.01});
  const PoseEstimate e = estimatePose(particles(list), kParams);
  ASSERT_EQ(2u, e.clusters.size());
  EXPECT_EQ(6u, e.clusters[0].count);
  EXPECT_NEAR(1.0, e.pose.x, kTol);
}

TEST(EstimatePose, BarelyWeightedBinsDoNotJoinClusters) {
  // A tracked pair in one bin holding weight 1, and a chain of particles
  // 0.5 m apart running from it to x = 5.1, each in its own bin with 9e-4
  // (recovery's random guesses): below 1e-3 of the heaviest bin, they stay
  // apart, and the estimate is the pair's mean.
  std::vector<Weighted> list = {{{0.1, 0.1, 0.0}, 0.5}, {{0.2, 0.1, 0.0}, 0.5}};
  for (int k = 1; k <= 10; ++k) list.push_back({{0.1 + 0.5 * k, 0.1, 0.0}, 9e-4});
  ParticleSet set = particles(list);
  const PoseEstimate e = estimatePose(set, kParams);  // join_weight_ratio 1e-3 by default
  ASSERT_EQ(11u, e.clusters.size());
  EXPECT_EQ(2u, e.clusters[0].count);
  expectEstimateNear({0.15, 0.1, 0.0}, e.pose, 1e-9);
  // Every bin joined: one cluster, its mean dragged along the chain to
  // (0.15 + 9e-4 * (10 * 0.1 + 0.5 * 55)) / (1 + 10 * 9e-4) = 0.174083.
  const PoseEstimate joined = estimatePose(set, ClusterParams{0.5, 0.5236, 0.0});
  ASSERT_EQ(1u, joined.clusters.size());
  EXPECT_NEAR(0.17565 / 1.009, joined.pose.x, 1e-9);
}

TEST(EstimatePose, EmptySetHasNoClusters) {
  const PoseEstimate e = estimatePose(ParticleSet(), kParams);
  EXPECT_TRUE(e.clusters.empty());
}

TEST(Summarize, UsesOnlyTheGivenIndices) {
  const ParticleSet set = particles({
      {{100.0, 0.0, 3.0}, 0.4},
      {{1.0, 2.0, 0.5}, 0.1},
      {{-100.0, 0.0, -3.0}, 0.4},
      {{3.0, 2.0, 0.5}, 0.3},
  });
  const Cluster c = summarize(set, {1, 3});
  EXPECT_EQ(2u, c.count);
  EXPECT_NEAR(0.4, c.weight, kTol);
  // x = (0.1 * 1 + 0.3 * 3) / 0.4 = 2.5; var = (0.1 * 1.5^2 + 0.3 * 0.5^2) / 0.4 = 0.75.
  expectEstimateNear({2.5, 2.0, 0.5}, c.mean);
  EXPECT_NEAR(0.75, c.covariance(0, 0), kTol);
  EXPECT_NEAR(0.0, c.covariance(1, 1), kTol);
  EXPECT_NEAR(0.0, c.covariance(2, 2), kTol);
}

// The bins by their definition, one particle at a time, against the packed
// keys: 21 particles (five blocks of four and a tail), with bin edges, a
// heading on each side of +-pi, headings one step of 2 pi outside (wrapped
// in the vector code) and one that needs the general wrap (the scalar code
// from its block on), non-finite coordinates and clouds far off.
TEST(PackClusterBins, EveryKeyAsByTheDefinition) {
  const double kNaN = std::numeric_limits<double>::quiet_NaN();
  const double kInf = std::numeric_limits<double>::infinity();
  const std::vector<double> xs = {0.0,   0.5,  -0.5, 0.4999999, -1e-300, 1.0,  2.5,
                                  -0.25, kNaN, kInf, -kInf,     1e9,     -1e9, 3.0,
                                  0.75,  1.25, -3.0, 7.0,       0.1,     0.2,  0.3};
  const std::vector<double> ys = {0.0,  0.25, 0.5, -0.5, 1.0, kNaN, 0.0,  -kInf, 0.0, 0.0, 0.0,
                                  1e12, 0.0,  3.5, -2.0, 0.5, 1.0,  -1.0, 0.0,   0.0, 0.0};
  const std::vector<double> yaws = {0.0,  M_PI, -M_PI, M_PI - 1e-12, -M_PI + 1e-12, 0.5236, 4.0,
                                    -4.0, 1.0,  -1.0,  0.0,          2.0,           -2.0,   3.0,
                                    3.1,  -3.1, 0.0,   10.0,         0.2,           0.4,    kNaN};
  ParticleSet cloud;
  cloud.x = xs;
  cloud.y = ys;
  cloud.yaw = yaws;  // as they are: setPose would wrap them
  cloud.weight.assign(xs.size(), 1.0);
  const int64_t yaw_bins = 12;
  std::vector<uint64_t> keys(cloud.size());
  packClusterBins(cloud, 0.5, yaw_bins, keys.data());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double yaw01 = (normalizeAngle(yaws[i]) + M_PI) / (2.0 * M_PI);
    const uint64_t expected = BinTable::key(
        binIndex(xs[i], 0.5), binIndex(ys[i], 0.5),
        std::clamp<int64_t>(binIndex(yaw01, 1.0 / static_cast<double>(yaw_bins)), 0, 11));
    EXPECT_EQ(expected, keys[i]) << "particle " << i << " at " << xs[i] << ", " << ys[i] << ", "
                                 << yaws[i];
  }
  // And the keys unpack to the bins: (0.5, 0.25, pi) is in (1, 0) and the
  // last heading bin; heading 0 in bin 6 of 12; x = 1e9 m clamps to 2^20 - 1.
  const BinTable::Bin b = BinTable::unpack(keys[1]);
  EXPECT_EQ(1, b.x);
  EXPECT_EQ(0, b.y);
  EXPECT_EQ(11, b.yaw);
  EXPECT_EQ(6, BinTable::unpack(keys[0]).yaw);
  EXPECT_EQ((int64_t{1} << 20) - 1, BinTable::unpack(keys[11]).x);
}

}  // namespace
}  // namespace pf
