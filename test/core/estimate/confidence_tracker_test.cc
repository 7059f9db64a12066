// ConfidenceTracker: the verdict after an initialisation, held after a jump
// and while a second place holds real weight, and demoted while the scans fit
// worse than usual for too long.
#include "pf_localization/core/estimate/confidence_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "pf_localization/core/estimate/hypotheses.h"

namespace pf {
namespace {

// A tight cloud of 200 particles around `at`: one cluster, a few cm wide.
ParticleSet tightCloud(const Pose2& at) {
  ParticleSet s;
  s.resize(200);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double d = 0.01 * (static_cast<double>(i % 5) - 2.0);
    s.setPose(i, {at.x + d, at.y - d, at.yaw + d});
  }
  s.setUniformWeights();
  return s;
}

class ConfidenceTrackerTest : public ::testing::Test {
 protected:
  void assessLocalized() {
    const ParticleSet cloud = tightCloud(at_);
    tracker_.assess(cloud, estimatePose(cloud, ClusterParams()), 0.95, params_);
    ASSERT_EQ(LocalizationState::kLocalized, tracker_.confidence().state)
        << tracker_.confidence().reason;
  }

  const Pose2 at_{2.0, 1.0, 0.3};
  ConfidenceParams params_;
  ConfidenceTracker tracker_;
};

TEST_F(ConfidenceTrackerTest, AfterAnInitialisationItIsUncertain) {
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.1, 0.2, 0.05).asDiagonal();
  tracker_.restart(cov);
  EXPECT_EQ(LocalizationState::kUncertain, tracker_.confidence().state);
  EXPECT_EQ(LocalizationState::kUncertain, tracker_.fitState());
  EXPECT_EQ(cov, tracker_.confidence().covariance);
}

TEST_F(ConfidenceTrackerTest, AJumpHoldsThePublishedVerdictButNotTheFitState) {
  assessLocalized();
  tracker_.holdAfterJump(std::nullopt, at_, params_);  // no previous estimate
  EXPECT_EQ(LocalizationState::kLocalized, tracker_.confidence().state);
  tracker_.holdAfterJump(compose(at_, {2.0, 0.0, 0.0}), at_, params_);
  EXPECT_EQ(LocalizationState::kUncertain, tracker_.confidence().state);
  EXPECT_EQ(LocalizationState::kLocalized, tracker_.fitState());
}

// The estimate's clusters with these weights, heaviest first, 3 m apart.
PoseEstimate placesWithWeights(const std::vector<double>& weights) {
  PoseEstimate e;
  for (std::size_t k = 0; k < weights.size(); ++k) {
    Cluster c;
    c.weight = weights[k];
    c.mean = {3.0 * static_cast<double>(k), 0.0, 0.0};
    c.count = 100;
    e.clusters.push_back(c);
  }
  return e;
}

TEST_F(ConfidenceTrackerTest, ASecondPlaceWithAShareOfTheWeightHoldsThePublishedVerdict) {
  // The simulated warehouse's global localization: twin aisles at 0.85 and
  // 0.15 of the weight, the lighter one the true place. 0.15 / 0.85 is no
  // rival (rival_weight_ratio 0.2), but pf_hypotheses lists both places.
  assessLocalized();
  tracker_.holdWhileAmbiguous(
      hypothesesOf(placesWithWeights({0.85, 0.15}), params_.rival_weight_ratio).count);
  EXPECT_EQ(LocalizationState::kUncertain, tracker_.confidence().state);
  EXPECT_NE(std::string::npos, tracker_.confidence().reason.find("1 other place"))
      << tracker_.confidence().reason;
  EXPECT_EQ(LocalizationState::kLocalized, tracker_.fitState());
  // Below kMinHypothesisShare the second cluster is no place of its own.
  assessLocalized();
  tracker_.holdWhileAmbiguous(
      hypothesesOf(placesWithWeights({0.96, 0.04}), params_.rival_weight_ratio).count);
  EXPECT_EQ(LocalizationState::kLocalized, tracker_.confidence().state);
}

TEST_F(ConfidenceTrackerTest, AFitBelowTheTriggerForLongerThanPatienceDemotes) {
  assessLocalized();
  tracker_.demoteAfterLowFit(5.0, 5);
  EXPECT_EQ(LocalizationState::kLocalized, tracker_.confidence().state);
  tracker_.demoteAfterLowFit(6.0, 5);
  EXPECT_EQ(LocalizationState::kUncertain, tracker_.confidence().state);
  EXPECT_NE(std::string::npos, tracker_.confidence().reason.find("for 6 views"));
}

// Patience counts views (view_share.h): updates a fifth of a view apart
// demote only after as much motion as whole-view updates do.
TEST_F(ConfidenceTrackerTest, PatienceCountsViewsNotUpdates) {
  assessLocalized();
  tracker_.demoteAfterLowFit(25 * 0.2, 5);
  EXPECT_EQ(LocalizationState::kLocalized, tracker_.confidence().state);
  tracker_.demoteAfterLowFit(26 * 0.2, 5);
  EXPECT_EQ(LocalizationState::kUncertain, tracker_.confidence().state);
  EXPECT_NE(std::string::npos, tracker_.confidence().reason.find("for 5.2 views"));
}

TEST_F(ConfidenceTrackerTest, AFitNarrowsThePublishedCovarianceWhereItConstrains) {
  const Eigen::Matrix3d cloud = Eigen::Vector3d(0.04, 0.01, 0.005).asDiagonal();
  tracker_.restart(cloud);
  // Sharp in y and yaw, nothing along x (a corridor).
  tracker_.addFit(Eigen::Vector3d(0.0, 1e-6, 1e-7).asDiagonal());
  const Eigen::Matrix3d c = tracker_.confidence().covariance;
  EXPECT_NEAR(cloud(0, 0), c(0, 0), 0.05 * cloud(0, 0));
  EXPECT_LT(c(1, 1), 1e-6);
  EXPECT_LT(c(2, 2), 1e-7);
}

// Twin places 10 m apart along x that the scan fits as well as the estimate.
class ConfidenceTrackerLookAlikesTest : public ConfidenceTrackerTest {
 protected:
  // An update at the estimate `at_`, tracked from `predicted`, whose scan
  // fits `as_good` twins as well (one listed, 10 m ahead).
  void update(const Pose2& predicted, std::size_t as_good) {
    assessLocalized();
    tracker_.holdAfterJump(predicted, at_, params_);
    tracker_.holdWhileAmbiguous(1, as_good);
    std::vector<LookAlikePlace> places;
    if (as_good > 0) places.push_back({compose({10.0, 0.0, 0.0}, at_), kFit});
    tracker_.coverLookAlikes(at_, kFit, places);
  }
  double stdX() const { return std::sqrt(tracker_.confidence().covariance(0, 0)); }

  static constexpr double kFit = -40.0;
};

TEST_F(ConfidenceTrackerLookAlikesTest, AfterAGlobalInitialisationTheCovarianceCoversTheTwins) {
  tracker_.restart(Eigen::Matrix3d::Identity() * 100.0, false);
  update(at_, 1);
  // Half the weight 10 m away: sqrt(0.5 * 10^2) = 7.07 m about the
  // estimate, where the cloud alone says cm.
  EXPECT_NEAR(std::sqrt(50.0), stdX(), 0.01);
  // A fit narrows the estimate's place, not the choice between the twins.
  tracker_.addFit(Eigen::Vector3d(1e-6, 1e-6, 1e-7).asDiagonal());
  EXPECT_GT(stdX(), 7.0);
  // A scan that fits no twin as well tells the place apart, for good.
  update(at_, 0);
  EXPECT_LT(stdX(), 0.05);
  update(at_, 1);
  EXPECT_LT(stdX(), 0.05);
}

TEST_F(ConfidenceTrackerLookAlikesTest, AGivenPoseTellsThePlaceApartUntilAFarJump) {
  tracker_.restart(Eigen::Matrix3d::Identity() * 0.01, true);
  update(at_, 1);
  EXPECT_LT(stdX(), 0.05);
  // A jump of 0.6 m is one (holdAfterJump) but cannot reach a twin.
  update(compose(at_, {0.6, 0.0, 0.0}), 1);
  EXPECT_LT(stdX(), 0.05);
  // 3 m beyond where the odometry put the last estimate, far outside
  // its spread: the scans alone chose this place.
  update(compose(at_, {3.0, 0.0, 0.0}), 1);
  EXPECT_NEAR(std::sqrt(50.0), stdX(), 0.01);
}

}  // namespace
}  // namespace pf
