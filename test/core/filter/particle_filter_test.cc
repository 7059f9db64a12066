#include "pf_localization/core/filter/particle_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/drive_and_track.h"
#include "support/exception_message.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

constexpr double kRes = 0.05;

// --- A synthetic world ---------------------------------------------------------

// test/support's rooms: a room of width x height metres in 0.05 m cells, with
// one-cell walls and the given boxes filled.
OccupancyGrid room(double width, double height, const std::vector<test::Box>& boxes) {
  return test::room(width, height, kRes, boxes);
}

// The room most tests drive in: 4 m x 3 m, two boxes, nothing symmetric.
using test::asymmetricRoom;

// 360 degrees, 2 degrees apart, from a laser 0.1 m ahead of the robot centre.
test::ScanSpec laserAhead() {
  test::ScanSpec spec;
  spec.sensor_pose = {0.1, 0.0, 0.0};
  return spec;
}

// That laser's scan with no return on any beam (180 NaN ranges).
LaserScan emptyScan() { return test::noReturnScan(laserAhead()); }

// The exact range to the first occupied cell along each beam, or NaN (no
// return) when the beam leaves the map first.
LaserScan simulateScan(const OccupancyGrid& grid, const Pose2& robot) {
  return test::simulateScan(grid, robot, laserAhead());
}

ParticleFilterParams baseParams() {
  ParticleFilterParams p;
  p.kld.min_particles = 300;
  p.kld.max_particles = 2000;
  p.seed = 1;
  return p;
}

Eigen::Matrix3d diag(double sx, double sy, double syaw) {
  return Eigen::Vector3d(sx * sx, sy * sy, syaw * syaw).asDiagonal();
}

double distance(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The odometry frame is not the map frame: map -> odom is kOdomInMap.
const Pose2 kOdomInMap{0.7, -0.4, 0.3};
Pose2 odomOf(const Pose2& truth) { return test::odometryOf(truth, kOdomInMap); }

// Drives `path` with the laser ahead, the odometry in kOdomInMap.
test::TrackingRun track(ParticleFilter* filter, const OccupancyGrid& grid,
                        const std::vector<Pose2>& path) {
  test::ScanSimulator scans(grid, laserAhead());
  return test::driveAndTrack(filter, path, &scans, kOdomInMap);
}

// A gently curving drive, 0.25 m per step, starting at (1, 1.5) facing +x.
std::vector<Pose2> trackingPath(int steps) {
  return test::stepPath({1.0, 1.5, 0.0}, {0.25, 0.0, 0.05}, steps);
}

// The message of the std::invalid_argument `f` throws ("" for none).
std::string whatOf(const std::function<void()>& f) {
  return test::whatOf<std::invalid_argument>(f);
}

// --- Parameters ----------------------------------------------------------------

void expectInvalid(const std::function<void(ParticleFilterParams&)>& change,
                   const std::string& name) {
  ParticleFilterParams p = baseParams();
  change(p);
  const std::string what = whatOf([&] { validate(p); });
  EXPECT_NE(std::string::npos, what.find(name))
      << "expected an error naming " << name << ", got \"" << what << "\"";
  EXPECT_FALSE(whatOf([&] { ParticleFilter filter(p); }).empty());
}

TEST(ParticleFilterParams, DefaultsAreValid) {
  EXPECT_NO_THROW(validate(ParticleFilterParams()));
  EXPECT_NO_THROW(validate(baseParams()));
}

TEST(ParticleFilterParams, InvalidValuesAreNamed) {
  using P = ParticleFilterParams;
  expectInvalid([](P& p) { p.kld.min_particles = -5; }, "min_particles");
  expectInvalid([](P& p) { p.kld.min_particles = 0; }, "min_particles");
  expectInvalid([](P& p) { p.kld.max_particles = -1; }, "max_particles");
  expectInvalid([](P& p) { p.kld.max_particles = 299; }, "max_particles");  // < min 300
  expectInvalid([](P& p) { p.sensor.sigma_hit = 0.0; }, "laser_sigma_hit");
  expectInvalid([](P& p) { p.sensor.sigma_hit = -0.2; }, "laser_sigma_hit");
  expectInvalid([](P& p) { p.motion.alpha1 = -0.1; }, "odom_alpha1");
  expectInvalid([](P& p) { p.motion.alpha3 = -1e-9; }, "odom_alpha3");
  expectInvalid([](P& p) { p.motion.alpha5 = NAN; }, "odom_alpha5");
  expectInvalid([](P& p) { p.sensor.z_hit = p.sensor.z_rand = 0.0; }, "laser_z_hit + laser_z_rand");
  expectInvalid([](P& p) { p.sensor.z_rand = -0.5; }, "laser_z_rand");
  expectInvalid([](P& p) { p.kld.confidence = 0.0; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.confidence = 1.0; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.confidence = 1.5; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.confidence = NAN; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.kld_err = 0.0; }, "kld_err");
  expectInvalid([](P& p) { p.resample_ess_fraction = 0.0; },
                "ParticleFilterParams::resample_ess_fraction");
  expectInvalid([](P& p) { p.resample_ess_fraction = 1.5; },
                "ParticleFilterParams::resample_ess_fraction");
  expectInvalid([](P& p) { p.update_min_d = -0.1; }, "update_min_d");
  expectInvalid([](P& p) { p.threads = -1; }, "threads");
  expectInvalid([](P& p) { p.sensor.max_beams = 0; }, "laser_max_beams");
  expectInvalid([](P& p) { p.sensor.max_distance = 0.0; }, "laser_likelihood_max_dist");
  expectInvalid([](P& p) { p.clusters.cell_xy = 0.0; }, "ClusterParams::cell_xy");
  expectInvalid([](P& p) { p.recovery.alpha_slow = 0.1, p.recovery.alpha_fast = 0.05; },
                "recovery_alpha_fast");
  // The message names the valid range too.
  ParticleFilterParams p = baseParams();
  p.kld.confidence = 2.0;
  EXPECT_NE(std::string::npos, whatOf([&] { validate(p); }).find("(0, 1)"));
}

// --- Initialisation --------------------------------------------------------------

TEST(ParticleFilter, StartsUninitialisedWithoutMap) {
  ParticleFilter filter(baseParams());
  EXPECT_FALSE(filter.hasMap());
  EXPECT_EQ(nullptr, filter.map());
  EXPECT_FALSE(filter.isInitialized());
  EXPECT_FALSE(filter.mapToOdom().has_value());
  EXPECT_THROW(filter.initializeUniform(), std::logic_error);
}

TEST(ParticleFilter, InitializeGaussian) {
  ParticleFilter filter(baseParams());
  filter.initializeGaussian({1.0, 2.0, 3.0}, diag(0.2, 0.1, 0.05));
  ASSERT_TRUE(filter.isInitialized());
  const ParticleSet& p = filter.particles();
  ASSERT_EQ(2000u, p.size());  // max_particles
  double sx = 0, sy = 0, sxx = 0, syy = 0, sw = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    sx += p.x[i];
    sy += p.y[i];
    sxx += (p.x[i] - 1.0) * (p.x[i] - 1.0);
    syy += (p.y[i] - 2.0) * (p.y[i] - 2.0);
    sw += p.weight[i];
    ASSERT_GT(p.yaw[i], -M_PI);
    ASSERT_LE(p.yaw[i], M_PI);
  }
  EXPECT_NEAR(1.0, sx / p.size(), 0.02);
  EXPECT_NEAR(2.0, sy / p.size(), 0.01);
  // Standard errors: 0.2 / sqrt(2 * 2000) = 0.0032 and half that; 5 of them.
  EXPECT_NEAR(0.2, std::sqrt(sxx / p.size()), 0.016);
  EXPECT_NEAR(0.1, std::sqrt(syy / p.size()), 0.008);
  EXPECT_NEAR(1.0, sw, 1e-9);
  // yaw 3.0 +- 0.05 wraps past pi for some particles; the estimate does not care.
  EXPECT_NEAR(0.0, angleDiff(filter.estimate().pose.yaw, 3.0), 0.01);
  EXPECT_NEAR(1.0, filter.estimate().pose.x, 0.02);
  // No update yet: no map -> odom.
  EXPECT_FALSE(filter.mapToOdom().has_value());
}

TEST(ParticleFilter, InitializeGaussianCorrelatedAndSemiDefinite) {
  ParticleFilter filter(baseParams());
  // x and y perfectly correlated, yaw fixed: every particle on the line y - 2 = x - 1.
  Eigen::Matrix3d cov;
  cov << 0.04, 0.04, 0.0,  //
      0.04, 0.04, 0.0,     //
      0.0, 0.0, 0.0;
  filter.initializeGaussian({1.0, 2.0, 0.5}, cov);
  const ParticleSet& p = filter.particles();
  double spread = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(p.x[i] - 1.0, p.y[i] - 2.0, 1e-9);
    EXPECT_EQ(0.5, p.yaw[i]);
    spread = std::max(spread, std::fabs(p.x[i] - 1.0));
  }
  EXPECT_GT(spread, 0.3);  // it is not collapsed to a point either
}

TEST(ParticleFilter, InitializeGaussianReproducesAFullCovariance) {
  // Largest variance on y, then yaw, then x, and x correlated with yaw: the
  // factorisation must pivot and undo the pivoting.
  Eigen::Matrix3d cov;
  cov << 0.01, 0.0, 0.012,  //
      0.0, 0.09, 0.0,       //
      0.012, 0.0, 0.04;
  ParticleFilterParams params = baseParams();
  params.kld.min_particles = params.kld.max_particles = 20000;
  ParticleFilter filter(params);
  filter.initializeGaussian({0.0, 0.0, 0.0}, cov);
  const ParticleSet& p = filter.particles();
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d d(p.x[i], p.y[i], p.yaw[i]);
    sample += d * d.transpose() / static_cast<double>(p.size());
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      // Within four standard errors of a Gaussian sample (co)variance:
      // sqrt((s_rr s_cc + s_rc^2) / n), at most 9e-4 here.
      const double se = std::sqrt((cov(r, r) * cov(c, c) + cov(r, c) * cov(r, c)) /
                                  static_cast<double>(p.size()));
      EXPECT_NEAR(cov(r, c), sample(r, c), 4.0 * se) << r << "," << c;
    }
  }
}

TEST(ParticleFilter, InitializeGaussianRejectsBadInput) {
  ParticleFilter filter(baseParams());
  EXPECT_THROW(filter.initializeGaussian({NAN, 0, 0}, diag(0.1, 0.1, 0.1)), std::invalid_argument);
  Eigen::Matrix3d asymmetric = diag(0.1, 0.1, 0.1);
  asymmetric(0, 1) = 0.01;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, asymmetric), std::invalid_argument);
  Eigen::Matrix3d negative = diag(0.1, 0.1, 0.1);
  negative(2, 2) = -0.01;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, negative), std::invalid_argument);
  Eigen::Matrix3d indefinite;   // symmetric, eigenvalues 1.5 and -0.5
  indefinite << 0.5, 1.0, 0.0,  //
      1.0, 0.5, 0.0,            //
      0.0, 0.0, 0.1;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, indefinite), std::invalid_argument);
  Eigen::Matrix3d nan = diag(0.1, 0.1, 0.1);
  nan(1, 1) = NAN;
  EXPECT_THROW(filter.initializeGaussian({0, 0, 0}, nan), std::invalid_argument);
  EXPECT_FALSE(filter.isInitialized());
}

TEST(ParticleFilter, InitializeUniformFillsFreeSpaceOnly) {
  ParticleFilter filter(baseParams());
  const OccupancyGrid grid = asymmetricRoom();
  EXPECT_FALSE(filter.setMap(grid));  // nothing to keep yet
  ASSERT_TRUE(filter.hasMap());
  EXPECT_EQ(grid.width(), filter.map()->width());
  filter.initializeUniform();
  const ParticleSet& p = filter.particles();
  ASSERT_EQ(2000u, p.size());
  double min_x = 1e9, max_x = -1e9, min_yaw = 1e9, max_yaw = -1e9;
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_TRUE(grid.isFreeAt(p.x[i], p.y[i])) << p.x[i] << ", " << p.y[i];
    min_x = std::min(min_x, p.x[i]);
    max_x = std::max(max_x, p.x[i]);
    min_yaw = std::min(min_yaw, p.yaw[i]);
    max_yaw = std::max(max_yaw, p.yaw[i]);
  }
  // Spread over the whole room and all headings.
  EXPECT_LT(min_x, 0.3);
  EXPECT_GT(max_x, 3.7);
  EXPECT_LT(min_yaw, -3.0);
  EXPECT_GT(max_yaw, 3.0);

  ParticleFilter walled(baseParams());
  walled.setMap(OccupancyGrid(4, 4, 0.1, {}, std::vector<int8_t>(16, 100)));
  EXPECT_THROW(walled.initializeUniform(), std::logic_error);
}

// --- Update gating -------------------------------------------------------------------

TEST(ParticleFilterUpdate, SkipsWithoutMap) {
  ParticleFilter filter(baseParams());
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const UpdateReport r = filter.update({0, 0, 0}, simulateScan(asymmetricRoom(), {1.0, 1.5, 0.0}));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNoMap, r.skip_reason) << skipMessage(r);
}

TEST(ParticleFilterUpdate, SkipsWhenNotInitialised) {
  ParticleFilter filter(baseParams());
  filter.setMap(asymmetricRoom());
  const UpdateReport r = filter.update({0, 0, 0}, simulateScan(asymmetricRoom(), {1.0, 1.5, 0.0}));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotInitialized, r.skip_reason) << skipMessage(r);
}

TEST(ParticleFilterUpdate, SkipsBadScansAndBadOdometry) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const LaserScan good = simulateScan(grid, {1.0, 1.5, 0.0});

  LaserScan empty = good;
  empty.ranges.clear();
  UpdateReport r = filter.update({0, 0, 0}, empty);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kBadScan, r.skip_reason) << skipMessage(r);

  LaserScan zero_increment = good;
  zero_increment.angle_increment = 0.0;
  r = filter.update({0, 0, 0}, zero_increment);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kBadScan, r.skip_reason) << skipMessage(r);
  // The detail names what is wrong.
  EXPECT_NE(std::string::npos, r.skip_detail.find("angle_increment")) << r.skip_detail;

  r = filter.update({NAN, 0, 0}, good);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kOdometryNotFinite, r.skip_reason) << skipMessage(r);

  // None of that counted as the first update.
  EXPECT_FALSE(filter.mapToOdom().has_value());
  EXPECT_TRUE(filter.update({0, 0, 0}, good).updated);
}

TEST(ParticleFilterUpdate, RunsOnTheFirstScanThenOnlyAfterMotion) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = baseParams();  // update_min_d 0.2 m, update_min_a pi/6
  // The odometry below moves while the scan stays: only the thresholds are
  // under test here, not the check that the scan still fits (see
  // AScanThatStopsFittingThePredictedPoseUpdatesAtOnce), nor the odometry
  // faults the stalled particles would find (SuspectOdometryUpdatesOnEveryScan).
  params.update_fit_drop = 0.0;
  params.motion.fault_fraction = 0.0;
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const LaserScan scan = simulateScan(grid, {1.0, 1.5, 0.0});
  const Pose2 odom0{5.0, 5.0, 2.0};

  UpdateReport r = filter.update(odom0, scan);
  EXPECT_TRUE(r.updated) << skipMessage(r);
  EXPECT_EQ(SkipReason::kNone, r.skip_reason);
  EXPECT_TRUE(r.skip_detail.empty());
  EXPECT_GT(r.beams_used, 0);
  EXPECT_LE(r.beams_used, 60);  // max_beams

  r = filter.update(odom0, scan);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotMoved, r.skip_reason) << skipMessage(r);

  // 0.19 m, then 0.5 rad: below both thresholds.
  EXPECT_FALSE(filter.update(compose(odom0, {0.19, 0.0, 0.0}), scan).updated);
  EXPECT_FALSE(filter.update(compose(odom0, {0.0, 0.0, 0.5}), scan).updated);
  // The robot went back: still not moved since the last update.
  EXPECT_FALSE(filter.update(odom0, scan).updated);

  // requestNoMotionUpdate forces one update, once.
  filter.requestNoMotionUpdate();
  EXPECT_TRUE(filter.update(odom0, scan).updated);
  EXPECT_FALSE(filter.update(odom0, scan).updated);

  // 0.21 m sideways (the direction does not matter) or 0.55 rad is enough.
  const Pose2 odom1 = compose(odom0, {0.0, -0.21, 0.0});
  EXPECT_TRUE(filter.update(odom1, scan).updated);
  const Pose2 odom2 = compose(odom1, {0.0, 0.0, -0.55});
  EXPECT_TRUE(filter.update(odom2, scan).updated);
  EXPECT_FALSE(filter.update(odom2, scan).updated);
}

TEST(ParticleFilterUpdate, NanOnlyScanIsSkippedWithAReason) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const std::vector<double> before = filter.particles().x;

  const UpdateReport r = filter.update({0, 0, 0}, emptyScan());  // 180 NaN ranges
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNoValidBeam, r.skip_reason) << skipMessage(r);
  EXPECT_EQ(0, r.beams_used);
  EXPECT_EQ(180, r.beams_dropped);
  EXPECT_EQ(before, filter.particles().x);
  EXPECT_FALSE(filter.mapToOdom().has_value());
  // The next usable scan is still the first one.
  EXPECT_TRUE(filter.update({0, 0, 0}, simulateScan(grid, {1.0, 1.5, 0.0})).updated);
}

// With noiseless motion and all particles at one pose, the particles move
// exactly by the odometry and the sensor update cannot change them.
ParticleFilterParams exactParams() {
  ParticleFilterParams p = baseParams();
  p.kld.min_particles = 10;
  p.kld.max_particles = 10;
  p.motion.alpha1 = p.motion.alpha2 = p.motion.alpha3 = p.motion.alpha4 = p.motion.alpha5 = 0.0;
  // Nor may recovery: the scans below deliberately disagree with the motion.
  p.recovery.alpha_slow = p.recovery.alpha_fast = 0.0;
  p.recovery.expansion_ratio = 0.0;
  return p;
}

// exactParams with 500 particles, an update on every scan and augmented
// MCL's averages on (expansion resetting stays off): for the recovery tests.
ParticleFilterParams recoveryParams() {
  ParticleFilterParams p = exactParams();
  p.kld.min_particles = p.kld.max_particles = 500;
  p.recovery.alpha_slow = 0.01;
  p.recovery.alpha_fast = 0.2;
  p.update_min_d = p.update_min_a = 0.0;
  return p;
}

// An update on `scan` with the odometry at rest that counts a whole new view
// (view_share.h), as the recovery tests' robot is carried without odometry:
// a requested update (amcl's request_nomotion_update) does. Without the
// request, a scan taken where the odometry has not moved brings no new view.
UpdateReport viewUpdate(ParticleFilter* filter, const LaserScan& scan) {
  filter->requestNoMotionUpdate();
  return filter->update({0.0, 0.0, 0.0}, scan);
}

// The recovery tests' robot: tracked at kTracked for five scans, then moved
// to kMoved (1.3 m away and turned) without the odometry seeing it.
const Pose2 kTracked{1.0, 1.5, 0.2};
const Pose2 kMoved{2.0, 2.2, 1.5};

void trackFiveScans(const OccupancyGrid& grid, ParticleFilter* filter,
                    const Eigen::Matrix3d& start_cov = Eigen::Matrix3d::Zero()) {
  filter->setMap(grid);
  filter->initializeGaussian(kTracked, start_cov);
  const LaserScan good = simulateScan(grid, kTracked);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(viewUpdate(filter, good).updated);
}

// Feeds scans taken at kMoved until recovery injects (five at most).
UpdateReport updateUntilInjection(const OccupancyGrid& grid, ParticleFilter* filter) {
  UpdateReport r;
  for (int k = 0; k < 5 && r.injected == 0; ++k) {
    r = viewUpdate(filter, simulateScan(grid, kMoved));
  }
  return r;
}

TEST(ParticleFilterUpdate, ACollapsedFitSpreadsTheSurvivors) {
  // Expansion resetting: tracking well at `start`, then the robot is pushed
  // 0.5 m sideways without odometry seeing it. That scan fits far worse than
  // usual, and the resampled particles are spread to search nearby.
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.recovery.expansion_ratio = 0.3;
  params.recovery.expansion_std_xy = 0.3;
  ParticleFilter filter(params);
  filter.setMap(grid);
  const Pose2 start{1.0, 1.5, 0.2};
  filter.initializeGaussian(start, Eigen::Matrix3d::Zero());
  const LaserScan scan = simulateScan(grid, start);
  for (int k = 0; k < 3; ++k) {
    const UpdateReport r = viewUpdate(&filter, scan);
    ASSERT_TRUE(r.updated);
    EXPECT_FALSE(r.expanded) << "update " << k;
  }
  const UpdateReport pushed = viewUpdate(&filter, simulateScan(grid, {1.0, 2.0, 0.2}));
  ASSERT_TRUE(pushed.updated);
  EXPECT_TRUE(pushed.expanded);
  double spread = 0.0;
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    spread = std::max(
        spread, std::hypot(filter.particles().x[i] - start.x, filter.particles().y[i] - start.y));
  }
  EXPECT_GT(spread, 0.5);  // all particles sat exactly at `start` before
}

// Tracks at `start` on `grid`, then feeds scans taken 1 m away that fit far
// worse than the usual ones; returns the random particles recovery injected.
std::size_t injectedAfterScansStopFitting(const OccupancyGrid& grid) {
  // The scans are simulated on the mapped room, whatever `grid` is.
  ParticleFilter filter(recoveryParams());
  filter.setMap(grid);
  filter.initializeGaussian(kTracked, Eigen::Matrix3d::Zero());
  const LaserScan good = simulateScan(asymmetricRoom(), kTracked);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(viewUpdate(&filter, good).updated);
  const LaserScan moved = simulateScan(asymmetricRoom(), kMoved);
  std::size_t injected = 0;
  for (int k = 0; k < 5; ++k) {
    const UpdateReport r = viewUpdate(&filter, moved);
    EXPECT_TRUE(r.updated) << skipMessage(r);
    injected += r.injected;
  }
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_TRUE(filter.particles().pose(i).isFinite());
  }
  EXPECT_TRUE(filter.estimate().pose.isFinite());
  return injected;
}

TEST(ParticleFilterUpdate, RecoveryInjectsOnlyWhereThereIsFreeSpace) {
  // The same room and scans, once as mapped and once with every free cell
  // unknown (found by fuzz_core: drawing from an empty free-cell list).
  const OccupancyGrid mapped = asymmetricRoom();
  std::vector<int8_t> data(mapped.data());
  for (int8_t& v : data) v = v == 0 ? -1 : v;
  const OccupancyGrid no_free(mapped.width(), mapped.height(), kRes, {}, data);
  ASSERT_TRUE(no_free.freeCells().empty());
  EXPECT_GT(injectedAfterScansStopFitting(mapped), 0u);
  EXPECT_EQ(injectedAfterScansStopFitting(no_free), 0u);
}

// The random particles injected on the first scan after the robot was
// carried from kTracked to kMoved, for a filter of at least 500 and at most
// `max_particles` particles and the given lost_share.
std::size_t injectedOnTheFirstLostScan(std::size_t max_particles, double lost_share) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.kld.max_particles = static_cast<int>(max_particles);
  params.recovery.lost_share = lost_share;
  params.resample_ess_fraction = 1.0;  // resample at every update: KLD shrinks the cloud
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter, diag(0.01, 0.01, 0.01));  // spread: the weights differ
  // Compact (569 particles, one bin or two) for a budget of 2000; not for one of 800.
  EXPECT_EQ(max_particles >= 2000, filter.particles().size() <= max_particles / 2);
  const UpdateReport r = filter.update({0.0, 0.0, 0.0}, simulateScan(grid, kMoved));
  EXPECT_TRUE(r.updated);
  EXPECT_EQ(LocalizationState::kLost, filter.confidence().state);
  return r.injected;
}

TEST(ParticleFilterUpdate, ACompactCloudThatIsLostSearchesAtOnceWithItsShareOfTheBudget) {
  // 500 particles of a budget of 2000 (compact): lost_share of the budget
  // is drawn on the very scan that finds the robot elsewhere. Without the
  // floor, the slow averages inject nothing until the second bad scan.
  EXPECT_EQ(1000u, injectedOnTheFirstLostScan(2000, 0.5));
  EXPECT_EQ(600u, injectedOnTheFirstLostScan(2000, 0.3));
  EXPECT_EQ(0u, injectedOnTheFirstLostScan(2000, 0.0));
  // 666 particles of a budget of 800 are more than (1 - 0.5) of it: a
  // cloud that is already searching is not thinned.
  EXPECT_EQ(0u, injectedOnTheFirstLostScan(800, 0.5));
}

TEST(ParticleFilterUpdate, InjectedParticlesWeighTheKidnapPriorTogether) {
  // Mixture-proposal weights: whatever their number, the random particles
  // hold kidnap_prior of the weight and the survivors the rest.
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.recovery.kidnap_prior = 0.01;
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter);
  const UpdateReport r = updateUntilInjection(grid, &filter);
  ASSERT_GT(r.injected, 0u);
  const ParticleSet& p = filter.particles();
  const std::size_t kept = p.size() - r.injected;
  double w_kept = 0.0, w_injected = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) (i < kept ? w_kept : w_injected) += p.weight[i];
  EXPECT_NEAR(0.99, w_kept, 1e-12);
  EXPECT_NEAR(0.01, w_injected, 1e-12);
  EXPECT_DOUBLE_EQ(0.01 / static_cast<double>(r.injected), p.weight.back());
}

TEST(ParticleFilterUpdate, RecoveryGuessesDoNotTemperTheNextScanAway) {
  // After an injection some particles are barely weighted guesses, so the
  // weights' effective sample size is below N. Tempering keeps a share of
  // that ESS; measured against N instead, a share above ESS / N could never
  // be kept, and every scan was tempered to an exponent of 0: ignored.
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.tempering_ess_fraction = params.tempering_ess_fraction_uncertain = 0.99;
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter);
  ASSERT_GT(updateUntilInjection(grid, &filter).injected, 0u);
  const double prior_ess = effectiveSampleSize(filter.particles().weight);
  ASSERT_LT(prior_ess, 0.99 * static_cast<double>(filter.particles().size()));
  const UpdateReport next = viewUpdate(&filter, simulateScan(grid, kMoved));
  ASSERT_TRUE(next.updated);
  EXPECT_GT(next.tempering, 0.0);
  EXPECT_LT(next.tempering, 1.0);
  EXPECT_NEAR(0.99 * prior_ess, next.ess, 0.01 * prior_ess);  // the bisection's target
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

// Where the odometry fault and fit tests start, every particle there.
const Pose2 kAtRest{1.5, 1.5, 0.0};

// Gives `filter` the map `grid`, puts every particle at kAtRest and updates
// on the scan taken there, with the odometry at its origin.
UpdateReport firstUpdateAtRest(ParticleFilter* filter, const OccupancyGrid& grid) {
  filter->setMap(grid);
  filter->initializeGaussian(kAtRest, Eigen::Matrix3d::Zero());
  return filter->update({0.0, 0.0, 0.0}, simulateScan(grid, kAtRest));
}

// exactParams with 1000 particles, of which odometry faults get 0.02 to 0.5.
ParticleFilterParams faultParams() {
  ParticleFilterParams params = exactParams();
  params.kld.min_particles = params.kld.max_particles = 1000;
  params.motion.fault_fraction = 0.02;
  params.motion.fault_fraction_max = 0.5;
  return params;
}

// The share of particles the filter gives to odometry faults after each of
// `steps` updates in which the odometry reports 0.3 m forwards along x and the
// scans are taken at `truth_step` metres per update from kAtRest.
std::vector<double> faultShares(double truth_step, int steps, double odom_step = 0.3) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = faultParams();
  params.update_min_d = 0.0;  // every step updates, however short
  params.motion.fault_margin = 0.05;
  ParticleFilter filter(params);
  firstUpdateAtRest(&filter, grid);
  std::vector<double> shares;
  for (int k = 1; k <= steps; ++k) {
    const Pose2 truth{kAtRest.x + truth_step * k, kAtRest.y, 0.0};
    const UpdateReport r = filter.update({odom_step * k, 0.0, 0.0}, simulateScan(grid, truth));
    EXPECT_TRUE(r.updated) << skipMessage(r);
    shares.push_back(r.fault_fraction);
  }
  return shares;
}

TEST(ParticleFilterUpdate, StepsTooShortToShowAFaultLeaveTheFaultShareAlone) {
  // 0.02 m steps reversed: twice that is below the 0.05 m margin within
  // which stalled particles spread anyway, so the scans cannot tell and the
  // share stays at the floor (it would climb to the maximum otherwise).
  for (double share : faultShares(-0.02, 4, 0.02)) EXPECT_DOUBLE_EQ(0.02, share);
  // 0.03 m steps reversed are 0.06 m off: observable, and the share rises.
  EXPECT_GT(faultShares(-0.03, 4, 0.03).back(), 0.02);
}

TEST(ParticleFilterUpdate, TheFaultShareRisesWhileTheOdometryIsReversedAndFallsBack) {
  // Right odometry: the faulty particles win nothing, the share stays at the floor.
  for (double share : faultShares(0.3, 3)) EXPECT_DOUBLE_EQ(0.02, share);
  // Odometry that reports forwards while the robot reverses: the reversed
  // particles win the weight, and the next step gives faults the maximum.
  const std::vector<double> reversed = faultShares(-0.3, 3);
  for (double share : reversed) EXPECT_DOUBLE_EQ(0.5, share);
}

// Whether the filter updates on a 0.3 m step below update_min_d (1 m),
// after one forced update on which the robot moved `truth_step` while the
// odometry said 0.3 m forwards.
bool updatesOnAShortStepAfter(double truth_step) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = faultParams();
  params.update_min_d = 1.0;
  params.update_min_a = 1.0;
  params.motion.fault_suspect_fraction = 0.1;
  ParticleFilter filter(params);
  firstUpdateAtRest(&filter, grid);
  filter.requestNoMotionUpdate();
  const Pose2 truth{kAtRest.x + truth_step, kAtRest.y, 0.0};
  EXPECT_TRUE(filter.update({0.3, 0.0, 0.0}, simulateScan(grid, truth)).updated);
  const UpdateReport next =
      filter.update({0.6, 0.0, 0.0}, simulateScan(grid, {truth.x + truth_step, truth.y, 0.0}));
  return next.updated;
}

TEST(ParticleFilterUpdate, SuspectOdometryUpdatesOnEveryScan) {
  // Right odometry: the next 0.3 m waits for update_min_d as usual.
  EXPECT_FALSE(updatesOnAShortStepAfter(0.3));
  // Reversed: the faulty particles won (share 0.5 >= 0.1), so the odometry
  // between updates is not trusted and the next scan updates at once.
  EXPECT_TRUE(updatesOnAShortStepAfter(-0.3));
}

// Whether the filter updates on a scan taken after the robot moved
// `truth_step` m forward while the odometry counted 0.15 m (below
// update_min_d 0.2 m).
UpdateReport shortStepUpdate(double truth_step, double fit_drop) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = exactParams();
  params.update_fit_drop = fit_drop;
  params.update_fit_distance = 0.1;
  ParticleFilter filter(params);
  EXPECT_TRUE(firstUpdateAtRest(&filter, grid).updated);
  return filter.update({0.15, 0.0, 0.0},
                       simulateScan(grid, {kAtRest.x + truth_step, kAtRest.y, 0.0}));
}

TEST(ParticleFilterUpdate, AScanThatStopsFittingThePredictedPoseUpdatesAtOnce) {
  // The odometry was right: the scan fits where it says, so the filter waits
  // for update_min_d.
  UpdateReport r = shortStepUpdate(0.15, 0.25);
  EXPECT_FALSE(r.updated);
  EXPECT_FALSE(r.fit_dropped);
  // The robot reversed while the encoders counted forwards: at the predicted
  // pose, 0.3 m from the truth, most beams miss the walls by more than 0.1 m.
  r = shortStepUpdate(-0.15, 0.25);
  EXPECT_TRUE(r.updated) << skipMessage(r);
  EXPECT_TRUE(r.fit_dropped);
  // The robot stalled: 0.15 m off, still a clear drop.
  EXPECT_TRUE(shortStepUpdate(0.0, 0.25).fit_dropped);
  // A drop of 1 can never happen: the check is off in effect, as with 0.
  EXPECT_FALSE(shortStepUpdate(-0.15, 1.0).updated);
  EXPECT_FALSE(shortStepUpdate(-0.15, 0.0).updated);
}

// The number of updates with bad scans before recovery injects (-1: none in
// 30), for a filter whose thresholds keep it in `state` whatever the fit
// (as it judges the fit; the published state of a "localized" one turns
// "uncertain" once the dip has lasted more than `patience` updates, or
// while a look-alike place fits as well).
int updatesBeforeInjection(int patience, LocalizationState state = LocalizationState::kUncertain,
                           int patience_localized = 10) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.recovery.patience = patience;
  params.recovery.patience_localized = patience_localized;
  params.confidence.lost_hit_fraction = params.confidence.localized_hit_fraction = 0.0;
  // Uncertain: no cloud is ever compact enough. Localized: every cloud is.
  const double std_limit = state == LocalizationState::kLocalized ? 100.0 : 1e-9;
  params.confidence.localized_std_xy = params.confidence.localized_std_yaw = std_limit;
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter);
  for (int k = 1; k <= 30; ++k) {
    const UpdateReport r = viewUpdate(&filter, simulateScan(grid, kMoved));
    // The dip starts at the second bad scan: k - 1 updates of low fit. The
    // room's walls also fit a half turn of the wrong estimate about as badly
    // as the estimate, and a look-alike as good holds the verdict too.
    const bool doubted =
        state == LocalizationState::kLocalized && (k - 1 > patience || r.look_alikes > 0);
    EXPECT_EQ(doubted ? LocalizationState::kUncertain : state, filter.confidence().state) << k;
    if (r.injected > 0) return k;
  }
  return -1;
}

TEST(ParticleFilterUpdate, AFilterThatIsNotLostWaitsOutShortDipsBeforeInjecting) {
  // The short-term fit (alpha_fast 0.2) falls below 0.7 of the long-term one
  // at the second bad scan: without patience that update injects; with it,
  // `patience` updates later.
  EXPECT_EQ(2, updatesBeforeInjection(0));
  EXPECT_EQ(5, updatesBeforeInjection(3));
  EXPECT_EQ(12, updatesBeforeInjection(10));
}

TEST(ParticleFilterUpdate, AFilterThatIsLocalizedWaitsLongerBeforeInjecting) {
  // The same dip, while the estimate's beams fit the map and the cloud is
  // compact: more likely a poor map there than a kidnapping (fr079 jumped
  // 28 m from random particles injected while 87 % of the beams fitted), so
  // patience_localized applies; but a dip that lasts is still searched.
  EXPECT_EQ(22, updatesBeforeInjection(0, LocalizationState::kLocalized, 20));
  EXPECT_EQ(22, updatesBeforeInjection(3, LocalizationState::kLocalized, 20));
  EXPECT_EQ(5, updatesBeforeInjection(3, LocalizationState::kLocalized, 3));
}

TEST(ParticleFilterUpdate, MotionIsAppliedFromTheLastUpdateOnly) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(exactParams());
  filter.setMap(grid);
  const Pose2 start{1.0, 1.5, 0.2};
  filter.initializeGaussian(start, Eigen::Matrix3d::Zero());
  const LaserScan scan = simulateScan(grid, start);

  // The first update after an initialisation does not move the particles,
  // whatever odometry came before.
  const Pose2 odom0{-3.0, 4.0, 1.0};
  ASSERT_TRUE(filter.update(odom0, scan).updated);
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_EQ(start.x, filter.particles().x[i]);
    EXPECT_EQ(start.y, filter.particles().y[i]);
    EXPECT_EQ(start.yaw, filter.particles().yaw[i]);
  }
  // Motion seen with a scan without usable beams is not lost: it is applied
  // with the next usable scan.
  const Pose2 odom1 = compose(odom0, {0.15, 0.0, 0.0});
  EXPECT_FALSE(filter.update(odom1, emptyScan()).updated);
  const Pose2 odom2 = compose(odom1, {0.3, 0.1, 0.2});
  ASSERT_TRUE(filter.update(odom2, scan).updated);
  const Pose2 expected = compose(start, between(odom0, odom2));
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_NEAR(expected.x, filter.particles().x[i], 1e-9);
    EXPECT_NEAR(expected.y, filter.particles().y[i], 1e-9);
    EXPECT_NEAR(expected.yaw, filter.particles().yaw[i], 1e-9);
  }
  // Re-initialising discards the odometry travelled since the last update.
  const Pose2 restart{2.0, 2.0, -1.0};
  filter.initializeGaussian(restart, Eigen::Matrix3d::Zero());
  ASSERT_TRUE(filter.update(compose(odom2, {1.0, 0.0, 1.0}), scan).updated);
  EXPECT_EQ(restart.x, filter.particles().x[0]);
  EXPECT_EQ(restart.yaw, filter.particles().yaw[0]);
}

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

TEST(ParticleFilterParams, SensorModelParametersAreNamed) {
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.laser_model_type = LaserModelType::kBeam;
        p.beam.lambda_short = 0.0;
      },
      "laser_lambda_short");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.laser_model_type = LaserModelType::kBeam;
        p.beam.z_short = -0.1;
      },
      "laser_z_short");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.laser_model_type = LaserModelType::kBeam;
        p.beam.z_max = NAN;
      },
      "laser_z_max");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.sensor.beam_skip = true;
        p.sensor.beam_skip_distance = 0.0;
      },
      "beam_skip_distance");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.sensor.beam_skip = true;
        p.sensor.beam_skip_threshold = 1.5;
      },
      "beam_skip_threshold");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.sensor.beam_skip = true;
        p.sensor.beam_skip_error_threshold = -0.1;
      },
      "beam_skip_error_threshold");
}

// Drives `path` (on free cells) and returns the step from which on the
// estimate stays within 0.2 m and 0.2 rad of the truth (-1: it never settles).
int settlesAt(ParticleFilter* filter, const OccupancyGrid& grid, const std::vector<Pose2>& path) {
  for (std::size_t k = 0; k < path.size(); ++k) {
    EXPECT_TRUE(grid.isFreeAt(path[k].x, path[k].y)) << "step " << k;
  }
  const test::TrackingRun run = track(filter, grid, path);
  for (std::size_t k = 0; k < run.steps.size(); ++k) {
    const UpdateReport& r = run.steps[k].report;
    EXPECT_TRUE(r.updated) << "step " << k << ": " << skipMessage(r);
  }
  return run.settledAt(0.2, 0.2);
}

TEST(ParticleFilter, GlobalLocalizationInAnAsymmetricRoom) {
  // An L-shaped room: 3 m x 2 m less a 1.2 m x 0.9 m block in its upper
  // right corner, plus a pillar in the upper arm. No half turn or mirror
  // image of it looks alike (for one that nearly does, see the next test).
  const OccupancyGrid grid = room(3.0, 2.0, {{1.8, 1.1, 3.0, 2.0}, {0.9, 1.5, 1.1, 1.7}});
  ParticleFilterParams params = baseParams();
  params.kld.min_particles = 500;
  params.kld.max_particles = 30000;
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeUniform();
  // Along +x under the block, a half turn in place, and back along -x.
  std::vector<Pose2> path{{0.6, 0.8, 0.0}};
  test::driveOn(&path, {0.25, 0.0, 0.0}, 6);      // to (2.1, 0.8), 0.3 m below the block
  test::driveOn(&path, {0.0, 0.0, M_PI / 4}, 4);  // facing -x
  test::driveOn(&path, {0.25, 0.0, 0.0}, 4);      // to (1.1, 0.8)
  const int converged_at = settlesAt(&filter, grid, path);
  EXPECT_GE(converged_at, 0) << "never settled on the true pose";
  EXPECT_LE(converged_at, 5);
  EXPECT_LT(distance(path.back(), filter.estimate().pose), 0.2);
  // KLD-sampling shrank the cloud once it had converged.
  EXPECT_LT(filter.particles().size(), 2000u);
}

TEST(ParticleFilter, GlobalLocalizationIsNotCapturedByAHalfTurnAlias) {
  // A plain 3 m x 2 m rectangle looks the same turned by half a turn; only
  // three small obstacles tell the two apart. Untempered, one scan gives a
  // few particles near the mirror pose e^15 times the weight of the best one
  // near the truth, and the whole cloud collapses onto the alias for good
  // (with this seed, and for about a quarter of all seeds). Tempering keeps
  // both hypotheses until the obstacles decide.
  const OccupancyGrid grid =
      room(3.0, 2.0, {{2.2, 1.3, 3.0, 2.0}, {1.0, 0.0, 1.2, 0.7}, {0.3, 1.5, 0.5, 1.7}});
  ParticleFilterParams params = baseParams();
  params.seed = 4;
  params.kld.min_particles = 500;
  params.kld.max_particles = 5000;
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeUniform();
  std::vector<Pose2> path{{0.6, 1.1, 0.0}};
  test::driveOn(&path, {0.25, 0.0, 0.0}, 4);      // to (1.6, 1.1)
  test::driveOn(&path, {0.0, 0.0, M_PI / 4}, 2);  // facing +y
  test::driveOn(&path, {0.21, 0.0, 0.0}, 3);      // to (1.6, 1.73)
  test::driveOn(&path, {0.0, 0.0, M_PI / 4}, 2);  // facing -x
  test::driveOn(&path, {0.25, 0.0, 0.0}, 3);      // to (0.85, 1.73)
  const int converged_at = settlesAt(&filter, grid, path);
  EXPECT_GE(converged_at, 0) << "never settled on the true pose";
  EXPECT_LE(converged_at, 6);
  EXPECT_LT(distance(path.back(), filter.estimate().pose), 0.2);
}

// --- Map changes -------------------------------------------------------------------

TEST(ParticleFilter, SetMapKeepsParticlesWhenTheEstimateIsStillFree) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.05, 0.05, 0.05));
  ASSERT_TRUE(filter.update(odomOf({1.0, 1.5, 0.0}), simulateScan(grid, {1.0, 1.5, 0.0})).updated);
  const ParticleSet before = filter.particles();

  // The same room with an extra box elsewhere: particles stay.
  EXPECT_TRUE(filter.setMap(room(4.0, 3.0, {{2.5, 0.5, 3.0, 1.2}, {3.0, 2.0, 3.5, 2.5}})));
  EXPECT_TRUE(filter.isInitialized());
  EXPECT_EQ(before.x, filter.particles().x);
  EXPECT_EQ(before.yaw, filter.particles().yaw);
  EXPECT_TRUE(filter.mapToOdom().has_value());

  // A map with a box over the estimate: the particles are dropped.
  EXPECT_FALSE(filter.setMap(room(4.0, 3.0, {{0.5, 1.0, 1.5, 2.0}})));
  EXPECT_FALSE(filter.isInitialized());
  EXPECT_TRUE(filter.particles().empty());
  EXPECT_TRUE(filter.estimate().clusters.empty());
  EXPECT_FALSE(filter.mapToOdom().has_value());
  const UpdateReport r = filter.update(odomOf({1.0, 1.5, 0.0}), simulateScan(grid, {1, 1.5, 0}));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotInitialized, r.skip_reason) << skipMessage(r);
}

TEST(ParticleFilter, SetMapDropsParticlesWhenTheEstimateLeavesTheMap) {
  ParticleFilter filter(baseParams());
  filter.setMap(asymmetricRoom());
  filter.initializeGaussian({3.5, 2.5, 0.0}, diag(0.05, 0.05, 0.05));
  EXPECT_FALSE(filter.setMap(room(2.0, 2.0, {})));  // (3.5, 2.5) is outside
  EXPECT_FALSE(filter.isInitialized());
  EXPECT_THROW(filter.setMap(OccupancyGrid()), std::invalid_argument);
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
