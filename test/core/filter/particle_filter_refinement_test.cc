// ParticleFilter with refine_estimate: the scan fit of scan_refiner.h feeds
// the published estimate and map -> odom (scan_refiner_test.cc tests the fit
// itself). In a file of its own, in small_world.h's room, so that it stays
// apart from the filter's other tests.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <vector>

#include "core/expect_pose.h"
#include "core/small_world.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "support/drive_and_track.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

using small_world::castScan;
using small_world::kTruth;

ParticleFilterParams params() { return small_world::refinedParams(); }

// The odometry frame is not the map frame: map -> odom is kOdomInMap.
const Pose2 kOdomInMap{0.7, -0.4, 0.3};
Pose2 odomOf(const Pose2& truth) { return test::odometryOf(truth, kOdomInMap); }

const Eigen::Matrix3d kStartCov =
    Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.03 * 0.03).asDiagonal();

double distance(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

void expectPositiveSemiDefinite(const Eigen::Matrix3d& m) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  EXPECT_GE(eig.eigenvalues()(0), -1e-12) << m;
}

TEST(ParticleFilterRefinement, TheFittedPoseIsPublishedThroughMapToOdom) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilter filter(params());
  filter.setMap(grid);
  filter.initializeGaussian({kTruth.x + 0.04, kTruth.y - 0.03, kTruth.yaw + 0.02}, kStartCov);
  const Pose2 odom = odomOf(kTruth);
  const UpdateReport r = filter.update(odom, castScan(grid, kTruth));
  ASSERT_TRUE(r.updated) << skipMessage(r);
  ASSERT_TRUE(r.refinement.accepted) << r.refinement.rejection_detail;
  EXPECT_EQ(180, r.refinement.matched_beams);
  const PoseEstimate& e = filter.estimate();
  expectPoseNear(r.refinement.pose, e.pose, 0.0);
  // Beams end on the walls' faces, half a cell from the cells' centres that
  // the field measures to: the fit is that good, not better.
  EXPECT_LT(distance(kTruth, e.pose), 0.01);
  EXPECT_LT(std::fabs(angleDiff(kTruth.yaw, e.pose.yaw)), 0.005);
  // The cloud's mean stays with the clusters, further off.
  EXPECT_GT(distance(kTruth, e.clusters[0].mean), distance(kTruth, e.pose));
  // map -> odom is the fitted pose's.
  expectPoseNear(compose(e.pose, inverse(odom)), *filter.mapToOdom(), 1e-12);
  // The published covariances are what the cloud and the fit know
  // together: no wider than either where the fit constrains the pose.
  expectPositiveSemiDefinite(e.clusters[0].covariance - e.covariance);
  expectPositiveSemiDefinite(r.refinement.covariance - e.covariance);
  expectPositiveSemiDefinite(e.clusters[0].covariance - filter.confidence().covariance);
  EXPECT_GT(e.covariance.determinant(), 0.0);
}

TEST(ParticleFilterRefinement, ScansBetweenUpdatesAreFittedAndStandingStillIsNot) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilter filter(params());
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, kStartCov);
  ASSERT_TRUE(filter.update(odomOf(kTruth), castScan(grid, kTruth)).updated);

  // 5 cm on, below update_min_d: no filter update, but a fit. The odometry
  // says 6 cm, so only the fit puts the robot where it is.
  const Pose2 truth = compose(kTruth, {0.05, 0.0, 0.0});
  const Pose2 odom = odomOf(compose(kTruth, {0.06, 0.0, 0.0}));
  UpdateReport r = filter.update(odom, castScan(grid, truth));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotMoved, r.skip_reason) << skipMessage(r);
  ASSERT_TRUE(r.refinement.accepted) << r.refinement.rejection_detail;
  const Pose2 placed = compose(*filter.mapToOdom(), odom);
  EXPECT_LT(distance(truth, placed), 0.01);
  expectPoseNear(r.refinement.pose, placed, 1e-9);

  // The same odometry again: standing still, the last fit stands.
  const Pose2 map_to_odom = *filter.mapToOdom();
  r = filter.update(odom, castScan(grid, compose(truth, {0.002, 0.0, 0.0})));
  EXPECT_FALSE(r.refinement.accepted);
  EXPECT_EQ(ScanRejection::kNotMovedSinceFit, r.refinement.rejection);
  expectPoseNear(map_to_odom, *filter.mapToOdom(), 0.0);
}

TEST(ParticleFilterRefinement, StandingStillThePublishedPoseHolds) {
  // Standing still, the published pose moves less than 5 mm (std
  // dev) from scan to scan. With the defaults, noisy scans (2 cm, a Neato's)
  // and encoders that twitch by a tenth of a millimetre.
  const OccupancyGrid grid = small_world::room();
  ParticleFilterParams p;
  p.seed = 3;
  ParticleFilter filter(p);
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, kStartCov);
  test::ScanSpec spec;
  spec.noise_sigma = 0.02;
  test::ScanSimulator scans(grid, spec);
  std::vector<Pose2> published;
  for (int k = 0; k < 40; ++k) {
    const Pose2 twitch{k % 2 == 0 ? 1e-4 : -1e-4, 0.0, 0.0};
    const Pose2 odom = odomOf(compose(kTruth, twitch));
    filter.update(odom, scans.scanFrom(kTruth));
    if (k >= 5) published.push_back(compose(*filter.mapToOdom(), odom));
  }
  double mx = 0.0, my = 0.0;
  for (const Pose2& q : published) mx += q.x / published.size(), my += q.y / published.size();
  double var = 0.0;
  for (const Pose2& q : published) var += (std::pow(q.x - mx, 2) + std::pow(q.y - my, 2));
  const double std_dev = std::sqrt(var / published.size());
  EXPECT_LT(std_dev, 0.005);
  // It does not refit at all: what moves is the twitch of the encoders.
  EXPECT_LT(std_dev, 2e-4);
  EXPECT_LT(distance(kTruth, published.back()), 0.02);
}

TEST(ParticleFilterRefinement, AnOdometryFaultMakesTheFitStale) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilter filter(params());
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, kStartCov);
  ASSERT_TRUE(filter.update(odomOf(kTruth), castScan(grid, kTruth)).refinement.accepted);
  // Odometry 10 m away: an odometry fault, skipped; tracking resumes from
  // the new odometry with the estimate where it was, as without refinement.
  const Pose2 jumped = compose(odomOf(kTruth), {10.0, 0.0, 0.0});
  const UpdateReport r = filter.update(jumped, castScan(grid, kTruth));
  EXPECT_EQ(SkipReason::kOdometryJumped, r.skip_reason) << skipMessage(r);
  expectPoseNear(compose(filter.estimate().pose, inverse(jumped)), *filter.mapToOdom(), 1e-12);
}

TEST(ParticleFilterRefinement, OffPublishesTheCloudsMean) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilterParams p = params();
  p.refine_estimate = false;
  ParticleFilter filter(p);
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, kStartCov);
  const UpdateReport r = filter.update(odomOf(kTruth), castScan(grid, kTruth));
  ASSERT_TRUE(r.updated);
  EXPECT_FALSE(r.refinement.accepted);
  EXPECT_EQ(ScanRejection::kRefinementOff, r.refinement.rejection);
  expectPoseNear(filter.estimate().clusters[0].mean, filter.estimate().pose, 0.0);
  EXPECT_EQ(filter.estimate().clusters[0].covariance, filter.estimate().covariance);
}

TEST(ParticleFilterRefinement, ALostFilterIsNotRefined) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilter filter(params());
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, kStartCov);
  // Every beam ends 0.3 m from the robot, in the open: no wall anywhere near.
  LaserScan scan = castScan(grid, kTruth);
  for (float& range : scan.ranges) range = 0.3f;
  const UpdateReport r = filter.update(odomOf(kTruth), scan);
  ASSERT_TRUE(r.updated);
  ASSERT_EQ(LocalizationState::kLost, filter.confidence().state);
  EXPECT_FALSE(r.refinement.accepted);
  EXPECT_EQ(ScanRejection::kFilterLost, r.refinement.rejection);
  expectPoseNear(filter.estimate().clusters[0].mean, filter.estimate().pose, 0.0);
}

}  // namespace
}  // namespace pf
