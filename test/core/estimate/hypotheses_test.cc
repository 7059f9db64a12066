#include "pf_localization/core/estimate/hypotheses.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pf_localization/core/estimate/confidence.h"

namespace pf {
namespace {

// A cloud of `places`, each a tight group of 4 particles carrying `weight`
// between them, 3 m apart along x.
ParticleSet cloudAt(const std::vector<Pose2>& places, const std::vector<double>& weights) {
  ParticleSet set;
  set.resize(4 * places.size());
  for (std::size_t p = 0; p < places.size(); ++p) {
    for (std::size_t k = 0; k < 4; ++k) {
      const std::size_t i = 4 * p + k;
      set.setPose(i, {places[p].x + 0.05 * static_cast<double>(k % 2),
                      places[p].y + 0.05 * static_cast<double>(k / 2), places[p].yaw});
      set.weight[i] = weights[p] / 4.0;
    }
  }
  return set;
}

PoseEstimate estimateWithWeights(const std::vector<double>& weights) {
  PoseEstimate e;
  for (std::size_t k = 0; k < weights.size(); ++k) {
    Cluster c;
    c.weight = weights[k];
    c.mean = {static_cast<double>(k), 0.0, 0.0};
    c.count = 10 + k;
    e.clusters.push_back(c);
  }
  return e;
}

TEST(Hypotheses, TwinRoomsAreTwoHypothesesHeaviestFirstAsTheirClusters) {
  const ParticleSet cloud = cloudAt({{1.0, 7.6, 0.0}, {11.0, 7.6, 0.0}}, {0.45, 0.55});
  const PoseEstimate estimate = estimatePose(cloud, ClusterParams{});
  const Hypotheses h = hypothesesOf(estimate, 0.2);
  ASSERT_EQ(2u, h.count);
  ASSERT_EQ(2u, h.listed.size());
  EXPECT_NEAR(11.025, h.listed[0].pose.x, 1e-9);
  EXPECT_NEAR(0.55, h.listed[0].weight, 1e-12);
  EXPECT_NEAR(1.025, h.listed[1].pose.x, 1e-9);
  EXPECT_NEAR(0.45, h.listed[1].weight, 1e-12);
  EXPECT_EQ(4u, h.listed[1].particles);
  // The cluster's own spread, not the whole cloud's 5 m.
  EXPECT_NEAR(0.025 * 0.025, h.listed[1].covariance(0, 0), 1e-9);
  EXPECT_NEAR(0.025 * 0.025, h.listed[1].covariance(1, 1), 1e-9);
}

TEST(Hypotheses, OneCompactClusterIsAListOfOne) {
  const ParticleSet cloud = cloudAt({{2.0, 3.0, 1.0}}, {1.0});
  const Hypotheses h = hypothesesOf(estimatePose(cloud, ClusterParams{}), 0.2);
  ASSERT_EQ(1u, h.count);
  ASSERT_EQ(1u, h.listed.size());
  EXPECT_NEAR(1.0, h.listed[0].weight, 1e-12);
  EXPECT_NEAR(1.0, h.listed[0].pose.yaw, 1e-6);
}

TEST(Hypotheses, EveryRivalOfTheVerdictIsListedHoweverSmallItsShare) {
  // 30 equal places: each 3.3 % of the weight, below kMinHypothesisShare,
  // but each a rival of the heaviest.
  const PoseEstimate estimate = estimateWithWeights(std::vector<double>(30, 1.0 / 30.0));
  const Hypotheses h = hypothesesOf(estimate, 0.2);
  EXPECT_EQ(30u, h.count);
  EXPECT_EQ(30u, h.listed.size());
  const ParticleSet cloud = cloudAt({{0.0, 0.0, 0.0}}, {1.0});
  const Confidence c = assessConfidence(cloud, estimate, 0.95, ConfidenceParams{});
  EXPECT_EQ(static_cast<int>(h.count) - 1, c.rivals);
  EXPECT_EQ(LocalizationState::kUncertain, c.state);
}

TEST(Hypotheses, APlaceWithAShareOfTheWeightIsListedThoughNoRival) {
  // global.bag's twin rooms: the wrong one 0.87, the true one 0.09 (0.10 of
  // the heaviest: no rival), then 0.04 scattered at 0.01 a cluster.
  const PoseEstimate estimate = estimateWithWeights({0.87, 0.09, 0.01, 0.01, 0.01, 0.01});
  const Hypotheses h = hypothesesOf(estimate, 0.2);
  EXPECT_EQ(2u, h.count);
  ASSERT_EQ(2u, h.listed.size());
  EXPECT_DOUBLE_EQ(1.0, h.listed[1].pose.x);
  // Weights are shares of the whole cloud, the unlisted clusters included.
  EXPECT_NEAR(0.87, h.listed[0].weight, 1e-12);
  EXPECT_NEAR(0.09, h.listed[1].weight, 1e-12);
  const ParticleSet cloud = cloudAt({{0.0, 0.0, 0.0}}, {1.0});
  EXPECT_EQ(0, assessConfidence(cloud, estimate, 0.95, ConfidenceParams{}).rivals);
  // Just below the share and below the rival ratio: one place.
  const Hypotheses one = hypothesesOf(estimateWithWeights({0.951, 0.049}), 0.2);
  EXPECT_EQ(1u, one.count);
  EXPECT_EQ(1u, hypothesesOf(estimateWithWeights({9.0, 0.4}), 0.2).count);
  // At the rival ratio exactly, with a share of 4.7 %: a rival, listed; 17
  // places of 4.2 % beside it, neither: not.
  std::vector<double> weights = {0.5, 0.1};
  weights.resize(19, 0.09);
  const Hypotheses rival = hypothesesOf(estimateWithWeights(weights), 0.2);
  EXPECT_EQ(2u, rival.count);
  EXPECT_LT(rival.listed[1].weight, kMinHypothesisShare);
}

TEST(Hypotheses, TenIdenticalAislesAreTenAndTheListIsCapped) {
  const std::vector<double> aisles(10, 0.1);
  const Hypotheses ten = hypothesesOf(estimateWithWeights(aisles), 0.2);
  EXPECT_EQ(10u, ten.count);
  ASSERT_EQ(10u, ten.listed.size());
  for (const Hypothesis& a : ten.listed) EXPECT_NEAR(0.1, a.weight, 1e-12);
  const Hypotheses capped = hypothesesOf(estimateWithWeights(aisles), 0.2, 4);
  EXPECT_EQ(10u, capped.count);
  ASSERT_EQ(4u, capped.listed.size());
  EXPECT_DOUBLE_EQ(3.0, capped.listed.back().pose.x);
  const Hypotheses many = hypothesesOf(estimateWithWeights(std::vector<double>(100, 0.01)), 0.2);
  EXPECT_EQ(100u, many.count);
  EXPECT_EQ(kMaxListedHypotheses, many.listed.size());
}

TEST(Hypotheses, NoClustersOrNoWeightAreNone) {
  EXPECT_EQ(0u, hypothesesOf(PoseEstimate{}, 0.2).count);
  const Hypotheses weightless = hypothesesOf(estimateWithWeights({0.0, 0.0}), 0.2);
  EXPECT_EQ(0u, weightless.count);
  EXPECT_TRUE(weightless.listed.empty());
}

// The estimate at the origin, 2 cm wide, and twin places the scan fits.
TEST(LookAlikeCovariance, CoversEquallyLikelyPlacesAndWeighsEachByItsFit) {
  const Pose2 at{0.0, 0.0, 0.0};
  const Eigen::Matrix3d own = Eigen::Vector3d(4e-4, 4e-4, 1e-4).asDiagonal();
  const double fit = -50.0;
  // No look-alike: the covariance stands.
  EXPECT_EQ(own, lookAlikeCovariance(at, own, fit, {}));
  // A twin 10 m along x that fits as well: half the weight there, so the
  // x variance about the estimate is 0.5 * 10^2 more; y and yaw as before.
  Eigen::Matrix3d c = lookAlikeCovariance(at, own, fit, {{{10.0, 0.0, 0.0}, fit}});
  EXPECT_NEAR(own(0, 0) + 50.0, c(0, 0), 1e-9);
  EXPECT_NEAR(own(1, 1), c(1, 1), 1e-12);
  EXPECT_NEAR(own(2, 2), c(2, 2), 1e-12);
  // One that fits 3 nats worse holds e^-3 / (1 + e^-3) of the weight.
  const double w = std::exp(-3.0) / (1.0 + std::exp(-3.0));
  c = lookAlikeCovariance(at, own, fit, {{{10.0, 0.0, 0.0}, fit - 3.0}});
  EXPECT_NEAR(own(0, 0) + w * 100.0, c(0, 0), 1e-9);
  // A half-turn twin at the same spot: yaw off by pi with half the weight.
  c = lookAlikeCovariance(at, own, fit, {{{0.0, 5.0, M_PI}, fit}});
  EXPECT_NEAR(own(2, 2) + 0.5 * M_PI * M_PI, c(2, 2), 1e-9);
  EXPECT_NEAR(own(1, 1) + 0.5 * 25.0, c(1, 1), 1e-9);
  // A place within LookAlikes::kMinShift of the estimate, or of a better
  // fitting place, is that place: counted once.
  c = lookAlikeCovariance(
      at, own, fit, {{{0.5, 0.0, 0.0}, fit}, {{10.0, 0.0, 0.0}, fit}, {{10.4, 0.0, 0.0}, fit}});
  EXPECT_NEAR(own(0, 0) + 50.0, c(0, 0), 1e-9);
  // A far better twin takes (nearly) all the weight, without overflow.
  c = lookAlikeCovariance(at, own, fit, {{{10.0, 0.0, 0.0}, fit + 2000.0}});
  EXPECT_NEAR(own(0, 0) + 100.0, c(0, 0), 1e-9);
}

}  // namespace
}  // namespace pf
