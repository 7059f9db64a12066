// ParticleFilter tracking a robot from a known start: map -> odom, the same
// particles for the same seed, tracking from an off initial guess with every
// laser model, a wide cloud whose beams fit left untempered, and finite weights
// when every particle scores zero.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"

namespace pf {
namespace {

using filter_world::asymmetricRoom;
using filter_world::baseParams;
using filter_world::diag;
using filter_world::distance;
using filter_world::emptyScan;
using filter_world::kOdomInMap;
using filter_world::room;
using filter_world::simulateScan;
using filter_world::track;
using filter_world::trackingPath;

TEST(ParticleFilter, MapToOdomIsEstimateComposedWithInverseOdometry) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.05, 0.05, 0.05));
  EXPECT_FALSE(filter.mapToOdom().has_value());
  const Pose2 odom{3.0, -2.0, 2.5};
  ASSERT_TRUE(filter.update(odom, simulateScan(grid, {1.0, 1.5, 0.0})).updated);
  ASSERT_TRUE(filter.mapToOdom().has_value());
  const Pose2 expected = compose(filter.estimate().pose, inverse(odom));
  const Pose2 actual = *filter.mapToOdom();
  EXPECT_NEAR(expected.x, actual.x, 1e-12);
  EXPECT_NEAR(expected.y, actual.y, 1e-12);
  EXPECT_NEAR(0.0, angleDiff(expected.yaw, actual.yaw), 1e-12);
  // And map -> odom (+) odom gives the estimate back.
  const Pose2 back = compose(actual, odom);
  EXPECT_NEAR(filter.estimate().pose.x, back.x, 1e-9);
  EXPECT_NEAR(filter.estimate().pose.y, back.y, 1e-9);
  EXPECT_NEAR(0.0, angleDiff(filter.estimate().pose.yaw, back.yaw), 1e-9);
}

// --- Determinism ---------------------------------------------------------------------

ParticleSet runTracking(uint64_t seed, int steps) {
  ParticleFilterParams params = baseParams();
  params.seed = seed;
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeGaussian({1.2, 1.3, 0.1}, diag(0.3, 0.3, 0.15));
  track(&filter, grid, trackingPath(steps));
  return filter.particles();
}

TEST(ParticleFilter, SameSeedSameParticlesDifferentSeedDifferent) {
  const ParticleSet a = runTracking(7, 3);
  const ParticleSet b = runTracking(7, 3);
  const ParticleSet c = runTracking(8, 3);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.yaw, b.yaw);
  EXPECT_EQ(a.weight, b.weight);
  EXPECT_NE(a.x, c.x);
}

// --- Localisation ----------------------------------------------------------------------

TEST(ParticleFilter, TracksFromAnOffInitialGuess) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  const std::vector<Pose2> path = trackingPath(10);
  // 0.3 m and 0.1 rad off the truth (1, 1.5, 0).
  filter.initializeGaussian({1.18, 1.26, 0.1}, diag(0.3, 0.3, 0.15));
  ASSERT_NEAR(0.3, distance(path[0], {1.18, 1.26, 0.0}), 1e-9);
  const test::TrackingRun run = track(&filter, grid, path);
  for (std::size_t k = 0; k < run.steps.size(); ++k) {
    const UpdateReport& r = run.steps[k].report;
    ASSERT_TRUE(r.updated) << "step " << k << ": " << skipMessage(r);
    EXPECT_GE(r.particles, 300u);
    EXPECT_LE(r.particles, 2000u);
  }
  const Pose2 estimate = run.last().estimate;
  EXPECT_LT(run.last().position_error, 0.1)
      << "estimate " << estimate.x << ", " << estimate.y << ", " << estimate.yaw;
  EXPECT_LT(run.last().yaw_error, 0.05);
  // map -> odom recovers the frame the odometry was expressed in.
  const Pose2 map_to_odom = *filter.mapToOdom();
  EXPECT_LT(distance(kOdomInMap, map_to_odom), 0.15);
  EXPECT_LT(std::fabs(angleDiff(kOdomInMap.yaw, map_to_odom.yaw)), 0.05);
  // A confident estimate: its covariance is small.
  EXPECT_LT(filter.estimate().covariance(0, 0), 0.05 * 0.05);
  EXPECT_LT(filter.estimate().covariance(1, 1), 0.05 * 0.05);
}

// The filter composes whichever sensor model laser_model_type names; each
// one must track on the same drive.
TEST(ParticleFilter, EveryLaserModelTracksFromAnOffInitialGuess) {
  const OccupancyGrid grid = asymmetricRoom();
  for (const LaserModelType type : {LaserModelType::kLikelihoodField,
                                    LaserModelType::kLikelihoodFieldProb, LaserModelType::kBeam}) {
    ParticleFilterParams params = baseParams();
    params.laser_model_type = type;
    params.sensor.beam_skip = true;  // used by kLikelihoodFieldProb only
    ParticleFilter filter(params);
    filter.setMap(grid);
    filter.initializeGaussian({1.18, 1.26, 0.1}, diag(0.3, 0.3, 0.15));
    const test::TrackingRun run = track(&filter, grid, trackingPath(10));
    for (std::size_t k = 0; k < run.steps.size(); ++k) {
      const UpdateReport& r = run.steps[k].report;
      ASSERT_TRUE(r.updated) << "model " << static_cast<int>(type) << ", step " << k;
      // Only the skipping model may leave beams out.
      if (type != LaserModelType::kLikelihoodFieldProb) {
        EXPECT_EQ(0, r.beams_skipped);
      }
    }
    EXPECT_LT(run.last().position_error, 0.1) << "model " << static_cast<int>(type);
    EXPECT_LT(run.last().yaw_error, 0.05) << "model " << static_cast<int>(type);
  }
}

// The tempering exponent of the second update of a filter started from a
// Gaussian of std `spread` m at the truth, tempering to keep 0.9 of the
// effective particles while uncertain (and none while localized).
double secondTempering(double spread, Confidence* after_first) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = baseParams();
  params.kld.min_particles = params.kld.max_particles = 1000;
  params.tempering_ess_fraction = 0.0;
  params.tempering_ess_fraction_uncertain = 0.9;
  params.confidence.localized_std_xy = 0.3;
  ParticleFilter filter(params);
  filter.setMap(grid);
  const Pose2 truth{1.5, 1.5, 0.0};
  filter.initializeGaussian(truth, diag(spread, spread, 0.02));
  EXPECT_TRUE(filter.update({0.0, 0.0, 0.0}, simulateScan(grid, truth)).updated);
  *after_first = filter.confidence();
  filter.requestNoMotionUpdate();
  return filter.update({0.0, 0.0, 0.0}, simulateScan(grid, truth)).tempering;
}

TEST(ParticleFilterUpdate, AWideCloudWhoseBeamsFitIsNotTempered) {
  // Wide (0.6 m) but one cluster whose estimate's beams fit: uncertain for
  // its spread alone, which caution would only preserve.
  Confidence c;
  EXPECT_EQ(1.0, secondTempering(0.6, &c));
  EXPECT_EQ(LocalizationState::kUncertain, c.state);
  EXPECT_EQ(0, c.rivals);
  EXPECT_NE(std::string::npos, c.reason.find("spread")) << c.reason;
}

// --- Degenerate likelihoods -------------------------------------------------------------

TEST(ParticleFilter, WeightsStayFiniteWhenEveryParticleScoresZero) {
  // Without the random component and with a narrow Gaussian, a beam ending
  // 2 m from any wall has likelihood exp(-0.5 (2 / 0.05)^2) = exp(-800),
  // which is 0 in double precision: every particle scores log 0 = -inf.
  ParticleFilterParams params = baseParams();
  params.sensor.z_rand = 0.0;
  params.sensor.sigma_hit = 0.05;
  params.sensor.max_distance = 2.0;
  const OccupancyGrid grid = room(8.0, 8.0, {});
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeGaussian({2.0, 4.0, 0.0}, diag(0.05, 0.05, 0.02));
  LaserScan scan = emptyScan();
  scan.sensor_pose = {};
  scan.ranges[90] = 2.0f;  // straight ahead, ending at the room's centre
  const UpdateReport r = filter.update({0, 0, 0}, scan);
  ASSERT_TRUE(r.updated) << skipMessage(r);
  double total = 0.0;
  for (double w : filter.particles().weight) {
    ASSERT_TRUE(std::isfinite(w));
    total += w;
  }
  EXPECT_NEAR(1.0, total, 1e-9);
  EXPECT_TRUE(std::isfinite(r.ess));
  EXPECT_TRUE(filter.estimate().pose.isFinite());
  EXPECT_LT(distance({2.0, 4.0, 0.0}, filter.estimate().pose), 0.1);
  // Evidence that rules out every particle alike tells them nothing: the
  // cloud keeps its 0.05 m spread instead of collapsing onto one particle.
  const ParticleSet& p = filter.particles();
  double mean = 0.0, var = 0.0;
  for (double x : p.x) mean += x / p.size();
  for (double x : p.x) var += (x - mean) * (x - mean) / p.size();
  EXPECT_GT(std::sqrt(var), 0.03);
}

}  // namespace
}  // namespace pf
