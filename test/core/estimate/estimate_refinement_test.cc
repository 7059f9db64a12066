// EstimateRefinement: the scan fit of the estimate at an update and between
// updates, and the map -> odom it gives.
#include "pf_localization/core/estimate/estimate_refinement.h"

#include <gtest/gtest.h>

#include "core/expect_pose.h"
#include "core/small_world.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "support/grid_from_rows.h"

namespace pf {
namespace {

using small_world::castScan;
using small_world::kTruth;

class EstimateRefinementTest : public ::testing::Test {
 protected:
  EstimateRefinementTest()
      : grid_(small_world::room()), model_(grid_, LikelihoodFieldModelParams()) {
    params_.refine_estimate = true;
    estimate_.pose = {kTruth.x + 0.04, kTruth.y - 0.03, kTruth.yaw + 0.02};
    estimate_.covariance = Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.03 * 0.03).asDiagonal();
  }

  OccupancyGrid grid_;
  LikelihoodFieldModel model_;
  ParticleFilterParams params_;
  PoseEstimate estimate_;
  EstimateRefinement refinement_;
  const Pose2 odom_{3.0, -1.0, 0.5};
};

TEST_F(EstimateRefinementTest, AtAnUpdateTheFitMovesTheEstimateOntoTheScan) {
  const PoseEstimate cloud = estimate_;
  const ScanRefinement r =
      refinement_.atUpdate(model_, castScan(grid_, kTruth), odom_, std::nullopt,
                           LocalizationState::kLocalized, params_, &estimate_);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  EXPECT_LT(std::hypot(estimate_.pose.x - kTruth.x, estimate_.pose.y - kTruth.y), 0.01);
  // What the cloud (the prior) and the fit know together: sharper than either.
  EXPECT_LE(estimate_.covariance(0, 0), r.covariance(0, 0) + 1e-12);
  EXPECT_LE(estimate_.covariance(0, 0), cloud.covariance(0, 0) + 1e-12);
  EXPECT_GT(estimate_.covariance(0, 0), 0.0);
  expectPoseNear(compose(r.pose, inverse(odom_)), refinement_.mapToOdom(cloud.pose, odom_), 1e-12);
}

TEST_F(EstimateRefinementTest, OffOrLostKeepsTheCloudsEstimate) {
  const Pose2 before = estimate_.pose;
  params_.refine_estimate = false;
  ScanRefinement r = refinement_.atUpdate(model_, castScan(grid_, kTruth), odom_, std::nullopt,
                                          LocalizationState::kLocalized, params_, &estimate_);
  EXPECT_EQ(ScanRejection::kRefinementOff, r.rejection);
  params_.refine_estimate = true;
  r = refinement_.atUpdate(model_, castScan(grid_, kTruth), odom_, std::nullopt,
                           LocalizationState::kLost, params_, &estimate_);
  EXPECT_EQ(ScanRejection::kFilterLost, r.rejection);
  expectPoseNear(before, estimate_.pose, 0.0);
  expectPoseNear(before, r.pose, 0.0);
  expectPoseNear(compose(before, inverse(odom_)), refinement_.mapToOdom(before, odom_), 1e-12);
}

TEST_F(EstimateRefinementTest, BetweenUpdatesAFitFollowsTheMapAndStandingStillKeepsIt) {
  ASSERT_TRUE(refinement_
                  .atUpdate(model_, castScan(grid_, kTruth), odom_, std::nullopt,
                            LocalizationState::kLocalized, params_, &estimate_)
                  .accepted);
  // The robot went 5 cm, the odometry says 6 cm.
  const Pose2 truth = compose(kTruth, {0.05, 0.0, 0.0});
  const Pose2 odom = compose(odom_, {0.06, 0.0, 0.0});
  ScanRefinement r = refinement_.betweenUpdates(model_, castScan(grid_, truth), odom, odom_,
                                                estimate_, LocalizationState::kLocalized, params_);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  const Pose2 placed = compose(refinement_.mapToOdom(estimate_.pose, odom_), odom);
  EXPECT_LT(std::hypot(placed.x - truth.x, placed.y - truth.y), 0.01);
  // Standing still: the last fit stands.
  r = refinement_.betweenUpdates(model_, castScan(grid_, truth), odom, odom_, estimate_,
                                 LocalizationState::kLocalized, params_);
  EXPECT_EQ(ScanRejection::kNotMovedSinceFit, r.rejection);
  expectPoseNear(placed, r.pose, 1e-12);
  // A lost filter is not fitted between updates either.
  EXPECT_EQ(ScanRejection::kNone, refinement_
                                      .betweenUpdates(model_, castScan(grid_, truth), odom, odom_,
                                                      estimate_, LocalizationState::kLost, params_)
                                      .rejection);
}

TEST_F(EstimateRefinementTest, AFitOfAnotherUpdateIsStale) {
  ASSERT_TRUE(refinement_
                  .atUpdate(model_, castScan(grid_, kTruth), odom_, std::nullopt,
                            LocalizationState::kLocalized, params_, &estimate_)
                  .accepted);
  const Pose2 other = compose(odom_, {10.0, 0.0, 0.0});  // an odometry jump
  expectPoseNear(compose(estimate_.pose, inverse(other)),
                 refinement_.mapToOdom(estimate_.pose, other), 1e-12);
  refinement_.reset();
  expectPoseNear(compose(estimate_.pose, inverse(odom_)),
                 refinement_.mapToOdom(estimate_.pose, odom_), 1e-12);
}

// 12 m of plain corridor, 2 m wide, in 0.1 m cells: a scan with a 5 m
// range sees two parallel walls and nothing that says how far along it is.
OccupancyGrid plainCorridor() {
  std::vector<std::string> rows(22, std::string(120, '.'));
  rows.front() = rows.back() = std::string(120, '#');
  return test::gridFromRows(rows, 0.1);
}

LaserScan shortScan(const OccupancyGrid& grid, const Pose2& at) {
  LaserScan scan = castScan(grid, at);
  for (float& r : scan.ranges) {
    if (r > 5.0f) r = 0.0f;  // beyond the range: no reading
  }
  return scan;
}

TEST(EstimateRefinementCorridor, AlongAPlainCorridorTheOdometryCarriesTheEstimate) {
  const OccupancyGrid grid = plainCorridor();
  const LikelihoodFieldModel model(grid, LikelihoodFieldModelParams());
  ParticleFilterParams params;
  params.refine_estimate = true;
  const Pose2 truth{6.0, 1.05, 0.0};
  PoseEstimate estimate;
  // The cloud is 1 m long along the corridor and its mean 0.8 m behind.
  estimate.pose = {5.2, 1.08, 0.02};
  estimate.covariance = Eigen::Vector3d(1.0, 0.01, 0.004).asDiagonal();
  const Pose2 predicted{6.03, 1.0, 0.01};  // the odometry, a few cm off
  EstimateRefinement refinement;
  const ScanRefinement r = refinement.atUpdate(model, shortScan(grid, truth), Pose2(), predicted,
                                               LocalizationState::kUncertain, params, &estimate);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  // Across and in yaw the scan decides, along the corridor the odometry.
  EXPECT_NEAR(predicted.x, estimate.pose.x, 1e-9);
  EXPECT_NEAR(truth.y, estimate.pose.y, 0.01);
  EXPECT_NEAR(truth.yaw, estimate.pose.yaw, 0.005);
  // And the covariance says so: the cloud's length along, sharp across, down
  // to what the two walls' offsets in their 0.1 m cells leave (0.1 / sqrt(24)
  // = 0.020 m), against the cloud's 0.1 m.
  EXPECT_NEAR(1.0, estimate.covariance(0, 0), 1e-6);
  EXPECT_LT(estimate.covariance(1, 1), 0.025 * 0.025);
  EXPECT_GT(estimate.covariance(1, 1), 0.019 * 0.019);
}

TEST(EstimateRefinementCorridor, APredictionBeyondTheCloudsSpreadIsNotBelieved) {
  const OccupancyGrid grid = plainCorridor();
  const LikelihoodFieldModel model(grid, LikelihoodFieldModelParams());
  ParticleFilterParams params;
  params.refine_estimate = true;
  PoseEstimate estimate;
  estimate.pose = {6.0, 1.05, 0.0};
  estimate.covariance = Eigen::Vector3d(0.04, 0.01, 0.004).asDiagonal();
  // 4 m off along the corridor, 20 of the cloud's std devs: an odometry
  // fault or a kidnapping, not drift.
  const Pose2 predicted{10.0, 1.05, 0.0};
  EstimateRefinement refinement;
  const ScanRefinement r =
      refinement.atUpdate(model, shortScan(grid, estimate.pose), Pose2(), predicted,
                          LocalizationState::kUncertain, params, &estimate);
  ASSERT_TRUE(r.accepted) << r.rejection_detail;
  EXPECT_NEAR(6.0, estimate.pose.x, 1e-6);
}

// 12 m of corridor, 2 m wide, in 0.1 m cells, with doorways at irregular
// spacing in both walls: where along it the robot is shows only in where
// the doorways are.
OccupancyGrid corridorWithDoors() {
  std::vector<std::string> rows(22, std::string(120, '.'));
  rows.front() = rows.back() = std::string(120, '#');
  const auto doorway = [&](std::string* wall, double x0, double x1) {
    for (int i = static_cast<int>(x0 * 10); i < static_cast<int>(x1 * 10); ++i) (*wall)[i] = '.';
  };
  doorway(&rows.front(), 3.0, 3.9);
  doorway(&rows.front(), 5.2, 6.1);
  doorway(&rows.front(), 8.9, 9.8);
  doorway(&rows.back(), 4.3, 5.0);
  doorway(&rows.back(), 7.6, 8.4);
  return test::gridFromRows(rows, 0.1);
}

// A fit at an update starts from the cloud's mean and, when the odometry's
// prediction lies elsewhere within the cloud's spread, from there too; the
// one whose end points lie better on the map wins.
class EstimateRefinementDoors : public ::testing::Test {
 protected:
  EstimateRefinementDoors()
      : grid_(corridorWithDoors()), model_(grid_, LikelihoodFieldModelParams()) {
    params_.refine_estimate = true;
  }

  // The estimate that atUpdate makes of a cloud at `cloud_mean` (1 m long
  // along the corridor) with the odometry predicting `predicted`.
  PoseEstimate fitted(const Pose2& cloud_mean, const Pose2& predicted) {
    PoseEstimate estimate;
    estimate.pose = cloud_mean;
    estimate.covariance = Eigen::Vector3d(0.25, 0.01, 0.004).asDiagonal();
    EstimateRefinement refinement;
    const ScanRefinement r =
        refinement.atUpdate(model_, shortScan(grid_, kTruth), Pose2(), predicted,
                            LocalizationState::kUncertain, params_, &estimate);
    EXPECT_TRUE(r.accepted) << r.rejection_detail;
    return estimate;
  }

  const Pose2 kTruth{6.0, 1.05, 0.0};
  OccupancyGrid grid_;
  LikelihoodFieldModel model_;
  ParticleFilterParams params_;
};

TEST_F(EstimateRefinementDoors, TheOdometrysPredictionFindsTheRightDoorways) {
  // 0.9 m ahead the doorways line up again, if worse: a fit from there stays.
  const Pose2 wrong{kTruth.x + 0.9, kTruth.y, 0.0};
  const ScanRefinement alone =
      ScanRefiner(model_.field(), params_.refiner)
          .refine(model_.prepare(shortScan(grid_, kTruth), params_.refiner.max_beams), wrong,
                  Eigen::Matrix3d(Eigen::Vector3d(0.25, 0.01, 0.004).asDiagonal()));
  ASSERT_TRUE(alone.accepted) << alone.rejection_detail;
  ASSERT_GT(alone.pose.x - kTruth.x, 0.8);
  // With the odometry 2 cm off as a second start, the fit finds the robot.
  const PoseEstimate estimate = fitted(wrong, {kTruth.x + 0.02, kTruth.y - 0.01, 0.005});
  EXPECT_NEAR(kTruth.x, estimate.pose.x, 0.02);
  EXPECT_NEAR(kTruth.y, estimate.pose.y, 0.02);
}

TEST_F(EstimateRefinementDoors, AWrongPredictionLosesToTheCloud) {
  // The odometry ran 0.9 m too far (a wheel slipped): its start fits worse.
  const PoseEstimate estimate =
      fitted({kTruth.x + 0.05, kTruth.y, 0.0}, {kTruth.x + 0.9, kTruth.y, 0.0});
  EXPECT_NEAR(kTruth.x, estimate.pose.x, 0.02);
  EXPECT_NEAR(kTruth.y, estimate.pose.y, 0.02);
}

}  // namespace
}  // namespace pf
