// Bad input to the core: every kind of broken scan, odometry, map and
// parameter must be refused with a reason that names what is wrong, and the
// filter must work again as soon as good input returns.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/motion/odometry_motion_model.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "support/exception_message.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr float kInff = std::numeric_limits<float>::infinity();

// A 4 m x 3 m room with one-cell walls and nothing in it.
OccupancyGrid room() { return test::room(4.0, 3.0, 0.05); }

// 180 beams from a laser at the robot centre, each the exact distance to the
// room's inner wall faces.
LaserScan scanAt(const Pose2& robot) { return test::simulateScan(room(), robot); }

ParticleFilterParams smallParams() {
  ParticleFilterParams p;
  p.kld.min_particles = 50;
  p.kld.max_particles = 200;
  p.seed = 3;
  return p;
}

const Pose2 kStart{2.0, 1.5, 0.3};

// A filter on the room, initialised around kStart, before its first update.
struct Fixture : ::testing::Test {
  Fixture() : filter(smallParams()) {
    filter.setMap(room());
    filter.initializeGaussian(kStart, Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal());
  }
  // The odometry frame coincides with the map frame here.
  UpdateReport goodUpdate(const Pose2& odom) { return filter.update(odom, scanAt(odom)); }
  ParticleFilter filter;
};

using test::whatOf;

// --- Scans ---------------------------------------------------------------------

using BadScan = Fixture;

TEST_F(BadScan, RangesAllInvalidSkipWithCountThenRecover) {
  const std::vector<float> bad = {kNaNf, kInff, -kInff, 0.0f, -1.0f, 1e9f, 0.01f};
  LaserScan scan = scanAt(kStart);
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) scan.ranges[i] = bad[i % bad.size()];
  const UpdateReport r = filter.update(kStart, scan);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(r.skip_reason, SkipReason::kNoValidBeam) << skipMessage(r);
  EXPECT_EQ(r.skip_detail, "180 of 180 beams invalid");
  EXPECT_EQ(r.beams_used, 0);
  EXPECT_EQ(r.beams_dropped, 180);
  EXPECT_FALSE(filter.mapToOdom().has_value());

  const UpdateReport good = goodUpdate(kStart);
  EXPECT_TRUE(good.updated) << skipMessage(good);
  EXPECT_TRUE(filter.mapToOdom().has_value());
}

TEST_F(BadScan, EachSingleKindOfInvalidRangeIsDropped) {
  for (const float v : {kNaNf, kInff, -kInff, 0.0f, -0.5f}) {
    LaserScan scan = scanAt(kStart);
    scan.ranges.assign(scan.ranges.size(), v);
    const UpdateReport r = filter.update(kStart, scan);
    EXPECT_FALSE(r.updated) << v;
    EXPECT_EQ(r.skip_reason, SkipReason::kNoValidBeam) << v << ": " << skipMessage(r);
  }
  EXPECT_TRUE(goodUpdate(kStart).updated);
}

struct ScanCase {
  const char* name;
  std::function<void(LaserScan*)> spoil;
  const char* reason;  // must appear in the skip reason
};

TEST_F(BadScan, UnusableScansSayWhyAndTheNextGoodScanWorks) {
  const std::vector<ScanCase> cases = {
      {"empty ranges", [](LaserScan* s) { s->ranges.clear(); }, "no ranges"},
      {"angle_increment 0", [](LaserScan* s) { s->angle_increment = 0.0; }, "angle_increment"},
      {"angle_increment NaN", [](LaserScan* s) { s->angle_increment = kNaN; }, "angle_increment"},
      {"angle_increment inf", [](LaserScan* s) { s->angle_increment = kInf; }, "angle_increment"},
      {"angle_min NaN", [](LaserScan* s) { s->angle_min = kNaN; }, "angle_min"},
      {"range_max == range_min", [](LaserScan* s) { s->range_max = s->range_min; }, "range_max"},
      {"range_max < range_min", [](LaserScan* s) { s->range_max = 0.01; }, "range_max"},
      {"range_max inf", [](LaserScan* s) { s->range_max = kInf; }, "range_max"},
      {"range_max NaN", [](LaserScan* s) { s->range_max = kNaN; }, "range_max"},
      {"range_min NaN", [](LaserScan* s) { s->range_min = kNaN; }, "range_min"},
      {"sensor x NaN", [](LaserScan* s) { s->sensor_pose.x = kNaN; }, "pose"},
      {"sensor y inf", [](LaserScan* s) { s->sensor_pose.y = kInf; }, "pose"},
      {"sensor yaw NaN", [](LaserScan* s) { s->sensor_pose.yaw = kNaN; }, "pose"},
  };
  Pose2 odom = kStart;
  for (const ScanCase& c : cases) {
    SCOPED_TRACE(c.name);
    LaserScan scan = scanAt(odom);
    c.spoil(&scan);
    const auto why = validateScan(scan);
    ASSERT_TRUE(why.has_value());
    EXPECT_NE(why->find(c.reason), std::string::npos) << *why;

    const UpdateReport r = filter.update(odom, scan);
    EXPECT_FALSE(r.updated);
    EXPECT_EQ(r.skip_reason, SkipReason::kBadScan) << skipMessage(r);
    EXPECT_EQ(r.skip_detail, *why);

    // Good input again: moved enough, so the filter updates.
    odom = compose(odom, {0.0, 0.0, 0.6});
    const UpdateReport good = goodUpdate(odom);
    EXPECT_TRUE(good.updated) << skipMessage(good);
    EXPECT_TRUE(filter.estimate().pose.isFinite());
  }
}

TEST(BadScanBeams, SelectBeamsDropsEveryInvalidRange) {
  LaserScan scan = scanAt(kStart);
  scan.ranges = {kNaNf, kInff, -kInff, 0.0f, -1.0f, 0.01f /* < range_min */, 8.0f /* = max */,
                 1.0f,  2.0f};
  std::size_t valid = 0;
  const std::vector<Beam> beams = selectBeams(scan, 0, 0.0, 0.0, &valid);
  ASSERT_EQ(valid, 2u);
  ASSERT_EQ(beams.size(), 2u);
  EXPECT_EQ(beams[0].range, 1.0f);
  EXPECT_EQ(beams[1].range, 2.0f);
  EXPECT_TRUE(selectBeams(LaserScan{}, 10).empty());
}

// --- Odometry ------------------------------------------------------------------

using BadOdometry = Fixture;

TEST_F(BadOdometry, NonFiniteOdometrySkipsWithReasonThenGoodOdometryWorks) {
  ASSERT_TRUE(goodUpdate(kStart).updated);
  const std::optional<Pose2> before = filter.mapToOdom();
  ASSERT_TRUE(before.has_value());
  for (const Pose2& bad : {Pose2{kNaN, 1.5, 0.0}, Pose2{2.0, kInf, 0.0}, Pose2{2.0, 1.5, kNaN},
                           Pose2{-kInf, kNaN, kInf}}) {
    const UpdateReport r = filter.update(bad, scanAt(kStart));
    EXPECT_FALSE(r.updated);
    EXPECT_EQ(r.skip_reason, SkipReason::kOdometryNotFinite) << skipMessage(r);
  }
  // Nothing about the filter changed.
  EXPECT_EQ(filter.mapToOdom()->x, before->x);
  EXPECT_EQ(filter.mapToOdom()->y, before->y);

  const Pose2 moved = compose(kStart, {0.4, 0.0, 0.0});
  const UpdateReport good = goodUpdate(moved);
  EXPECT_TRUE(good.updated) << skipMessage(good);
  EXPECT_TRUE(filter.estimate().pose.isFinite());
  EXPECT_LT(std::hypot(filter.estimate().pose.x - moved.x, filter.estimate().pose.y - moved.y),
            0.3);
}

TEST_F(BadOdometry, TenMetreJumpIsAFaultThatSkipsOneUpdate) {
  // The odometry frame coincides with the map until the jump; then odometry
  // reads 10 m further along x than the robot went (a reset, a glitch).
  ASSERT_TRUE(goodUpdate(kStart).updated);
  const Pose2 estimate_before = filter.estimate().pose;
  const Pose2 jump{10.0, 0.0, 0.0};
  const UpdateReport r = filter.update(compose(jump, kStart), scanAt(kStart));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(r.skip_reason, SkipReason::kOdometryJumped) << skipMessage(r);
  // The detail gives the step and the limit.
  EXPECT_EQ(r.skip_detail.rfind("10.0", 0), 0u) << r.skip_detail;
  // The particles stayed where they were...
  EXPECT_EQ(filter.estimate().pose.x, estimate_before.x);
  EXPECT_EQ(filter.estimate().pose.y, estimate_before.y);
  // ...and the next step is measured from the odometry after the jump: the
  // robot drives 0.4 m, the odometry says the same, and tracking carries on.
  const Pose2 moved = compose(kStart, {0.4, 0.0, 0.0});
  const UpdateReport good = filter.update(compose(jump, moved), scanAt(moved));
  EXPECT_TRUE(good.updated) << skipMessage(good);
  EXPECT_LT(std::hypot(filter.estimate().pose.x - moved.x, filter.estimate().pose.y - moved.y),
            0.1);
  // map -> odom now accounts for the jump.
  ASSERT_TRUE(filter.mapToOdom().has_value());
  EXPECT_NEAR(filter.mapToOdom()->x, -10.0, 0.1);
}

TEST(BadOdometryNoFilter, UpdateBeforeMapAndBeforeInitialisationSaySo) {
  ParticleFilter filter(smallParams());
  UpdateReport r = filter.update(kStart, scanAt(kStart));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(r.skip_reason, SkipReason::kNoMap) << skipMessage(r);
  filter.setMap(room());
  r = filter.update(kStart, scanAt(kStart));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(r.skip_reason, SkipReason::kNotInitialized) << skipMessage(r);
  filter.initializeUniform();
  EXPECT_TRUE(filter.update(kStart, scanAt(kStart)).updated);
}

// --- Maps ----------------------------------------------------------------------

TEST(BadMap, OneByOneFreeMapWorks) {
  ParticleFilter filter(smallParams());
  filter.setMap(OccupancyGrid(1, 1, 0.05, {}, {0}));
  ASSERT_NO_THROW(filter.initializeUniform());
  EXPECT_EQ(filter.particles().size(), 200u);
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_TRUE(filter.map()->isFreeAt(filter.particles().x[i], filter.particles().y[i]));
  }
  const UpdateReport r = filter.update({}, scanAt(kStart));  // every end point off the map
  EXPECT_TRUE(r.updated) << skipMessage(r);
  EXPECT_TRUE(filter.estimate().pose.isFinite());
  EXPECT_TRUE(filter.mapToOdom().has_value());
}

TEST(BadMap, NoFreeCellMakesGlobalLocalizationThrowLogicError) {
  for (const int8_t v : {int8_t{100}, int8_t{-1}, int8_t{50}}) {
    ParticleFilter filter(smallParams());
    filter.setMap(OccupancyGrid(3, 2, 0.05, {}, std::vector<int8_t>(6, v)));
    const std::string what = whatOf([&] { filter.initializeUniform(); });
    EXPECT_NE(what.find("free cell"), std::string::npos) << what;
    EXPECT_THROW(filter.initializeUniform(), std::logic_error);
    EXPECT_FALSE(filter.isInitialized());
  }
  // 1 x 1 occupied too.
  ParticleFilter filter(smallParams());
  filter.setMap(OccupancyGrid(1, 1, 0.05, {}, {100}));
  EXPECT_THROW(filter.initializeUniform(), std::logic_error);
  // A Gaussian start still works on such a map.
  EXPECT_NO_THROW(filter.initializeGaussian({}, Eigen::Matrix3d::Identity() * 0.01));
}

TEST(BadMap, GlobalLocalizationWithoutMapThrowsLogicError) {
  ParticleFilter filter(smallParams());
  EXPECT_THROW(filter.initializeUniform(), std::logic_error);
  EXPECT_THROW(filter.setMap(OccupancyGrid()), std::invalid_argument);
}

TEST(BadMap, GridConstructorNamesTheProblem) {
  const std::vector<int8_t> six(6, 0);
  const std::vector<std::pair<std::function<void()>, std::string>> cases = {
      {[&] { OccupancyGrid(0, 6, 0.05, {}, {}); }, "width and height"},
      {[&] { OccupancyGrid(-3, -2, 0.05, {}, six); }, "width and height"},
      {[&] { OccupancyGrid(3, 2, 0.0, {}, six); }, "resolution"},
      {[&] { OccupancyGrid(3, 2, -0.05, {}, six); }, "resolution"},
      {[&] { OccupancyGrid(3, 2, kNaN, {}, six); }, "resolution"},
      {[&] { OccupancyGrid(3, 2, kInf, {}, six); }, "resolution"},
      {[&] {
         OccupancyGrid(3, 2, 0.05, {kNaN, 0.0, 0.0}, six);
       },
       "origin"},
      {[&] {
         OccupancyGrid(3, 2, 0.05, {0.0, 0.0, kInf}, six);
       },
       "origin"},
      {[&] { OccupancyGrid(3, 2, 0.05, {}, std::vector<int8_t>(5, 0)); }, "5 cell values"},
  };
  for (const auto& c : cases) {
    EXPECT_THROW(c.first(), std::invalid_argument) << c.second;
    const std::string what = whatOf(c.first);
    EXPECT_NE(what.find(c.second), std::string::npos) << what;
  }
}

// --- Initial pose ----------------------------------------------------------------

TEST(BadInitialPose, NonFinitePoseOrBadCovarianceThrowsAndKeepsTheFilter) {
  ParticleFilter filter(smallParams());
  filter.setMap(room());
  filter.initializeGaussian(kStart, Eigen::Matrix3d::Identity() * 0.01);
  const Eigen::Matrix3d good = Eigen::Matrix3d::Identity() * 0.01;
  Eigen::Matrix3d asym = good;
  asym(0, 1) = 0.005;
  Eigen::Matrix3d negative = good;
  negative(1, 1) = -0.01;
  Eigen::Matrix3d nan = good;
  nan(2, 2) = kNaN;
  const std::vector<std::pair<std::function<void()>, std::string>> cases = {
      {[&] {
         filter.initializeGaussian({kNaN, 0.0, 0.0}, good);
       },
       "pose"},
      {[&] {
         filter.initializeGaussian({0.0, 0.0, kInf}, good);
       },
       "pose"},
      {[&] { filter.initializeGaussian(kStart, asym); }, "symmetric"},
      {[&] { filter.initializeGaussian(kStart, negative); }, "positive semi-definite"},
      {[&] { filter.initializeGaussian(kStart, nan); }, "finite"},
  };
  for (const auto& c : cases) {
    EXPECT_THROW(c.first(), std::invalid_argument) << c.second;
    const std::string what = whatOf(c.first);
    EXPECT_NE(what.find(c.second), std::string::npos) << what;
  }
  // The cloud from the good initialisation is still there and usable.
  EXPECT_EQ(filter.particles().size(), 200u);
  EXPECT_TRUE(filter.update(kStart, scanAt(kStart)).updated);
}

// --- Parameters ---------------------------------------------------------------

struct ParamCase {
  // Must appear in what(): the parameter's name, or for the filter's own
  // constants (not parameters) the option's struct and member.
  const char* name;
  std::function<void(ParticleFilterParams*)> spoil;
};

TEST(BadParams, EachInvalidParameterThrowsNamingIt) {
  const std::vector<ParamCase> cases = {
      {"min_particles", [](ParticleFilterParams* p) { p->kld.min_particles = 0; }},
      {"min_particles", [](ParticleFilterParams* p) { p->kld.min_particles = -5; }},
      {"max_particles", [](ParticleFilterParams* p) { p->kld.max_particles = -1; }},
      {"max_particles", [](ParticleFilterParams* p) { p->kld.max_particles = 0; }},
      {"max_particles",
       [](ParticleFilterParams* p) {
         p->kld.min_particles = 300;
         p->kld.max_particles = 200;
       }},
      {"kld_err", [](ParticleFilterParams* p) { p->kld.kld_err = 0.0; }},
      {"kld_err", [](ParticleFilterParams* p) { p->kld.kld_err = kNaN; }},
      {"kld_confidence", [](ParticleFilterParams* p) { p->kld.confidence = 0.0; }},
      {"kld_confidence", [](ParticleFilterParams* p) { p->kld.confidence = 1.0; }},
      {"kld_confidence", [](ParticleFilterParams* p) { p->kld.confidence = 1.5; }},
      {"kld_confidence", [](ParticleFilterParams* p) { p->kld.confidence = -0.2; }},
      {"kld_confidence", [](ParticleFilterParams* p) { p->kld.confidence = kNaN; }},
      {"KldParams::bin_xy", [](ParticleFilterParams* p) { p->kld.bin_xy = 0.0; }},
      {"KldParams::bin_yaw", [](ParticleFilterParams* p) { p->kld.bin_yaw = -0.1; }},
      {"update_min_d", [](ParticleFilterParams* p) { p->update_min_d = -0.1; }},
      {"update_min_a", [](ParticleFilterParams* p) { p->update_min_a = kNaN; }},
      {"ParticleFilterParams::update_fit_drop",
       [](ParticleFilterParams* p) { p->update_fit_drop = 1.5; }},
      {"RecoveryParams::lost_share", [](ParticleFilterParams* p) { p->recovery.lost_share = 1.0; }},
      {"RecoveryParams::patience_localized",
       [](ParticleFilterParams* p) { p->recovery.patience_localized = p->recovery.patience - 1; }},
      {"ParticleFilterParams::update_fit_distance",
       [](ParticleFilterParams* p) { p->update_fit_distance = 0.0; }},
      {"ParticleFilterParams::resample_ess_fraction",
       [](ParticleFilterParams* p) { p->resample_ess_fraction = 0.0; }},
      {"ParticleFilterParams::resample_ess_fraction",
       [](ParticleFilterParams* p) { p->resample_ess_fraction = 1.5; }},
      {"laser_sigma_hit", [](ParticleFilterParams* p) { p->sensor.sigma_hit = 0.0; }},
      {"laser_sigma_hit", [](ParticleFilterParams* p) { p->sensor.sigma_hit = -0.2; }},
      {"laser_sigma_hit", [](ParticleFilterParams* p) { p->sensor.sigma_hit = kNaN; }},
      {"laser_z_hit", [](ParticleFilterParams* p) { p->sensor.z_hit = -0.1; }},
      {"laser_z_rand", [](ParticleFilterParams* p) { p->sensor.z_rand = -0.1; }},
      {"laser_z_hit + laser_z_rand",
       [](ParticleFilterParams* p) {
         p->sensor.z_hit = 0.0;
         p->sensor.z_rand = 0.0;
       }},
      {"laser_likelihood_max_dist", [](ParticleFilterParams* p) { p->sensor.max_distance = 0.0; }},
      {"laser_max_beams", [](ParticleFilterParams* p) { p->sensor.max_beams = 0; }},
      {"laser_min_range", [](ParticleFilterParams* p) { p->sensor.range_min = -1.0; }},
      {"laser_max_range", [](ParticleFilterParams* p) { p->sensor.range_max = kInf; }},
      {"odom_alpha1", [](ParticleFilterParams* p) { p->motion.alpha1 = -0.1; }},
      {"odom_alpha2", [](ParticleFilterParams* p) { p->motion.alpha2 = -1e-9; }},
      {"odom_alpha3", [](ParticleFilterParams* p) { p->motion.alpha3 = -2.0; }},
      {"odom_alpha4", [](ParticleFilterParams* p) { p->motion.alpha4 = kNaN; }},
      {"odom_alpha5", [](ParticleFilterParams* p) { p->motion.alpha5 = -kInf; }},
      {"ClusterParams::cell_xy", [](ParticleFilterParams* p) { p->clusters.cell_xy = 0.0; }},
      {"ClusterParams::cell_yaw", [](ParticleFilterParams* p) { p->clusters.cell_yaw = kInf; }},
      {"recovery_alpha_slow", [](ParticleFilterParams* p) { p->recovery.alpha_slow = 2.0; }},
      {"recovery_alpha_fast",
       [](ParticleFilterParams* p) {
         p->recovery.alpha_slow = 0.1;
         p->recovery.alpha_fast = 0.05;
       }},
  };
  for (const ParamCase& c : cases) {
    ParticleFilterParams p = smallParams();
    c.spoil(&p);
    SCOPED_TRACE(c.name);
    EXPECT_THROW(validate(p), std::invalid_argument);
    EXPECT_THROW(ParticleFilter{p}, std::invalid_argument);
    const std::string what = whatOf([&] { ParticleFilter filter(p); });
    EXPECT_NE(what.find(c.name), std::string::npos) << what;
  }
  EXPECT_NO_THROW(validate(smallParams()));
}

TEST(BadParams, TheModelsRefuseBadParametersOnTheirOwn) {
  OdometryMotionParams m;
  m.alpha3 = -0.1;
  const std::string what = whatOf([&] { OdometryMotionModel model(m); });
  EXPECT_NE(what.find("odom_alpha3"), std::string::npos) << what;

  LikelihoodFieldModelParams s;
  s.sigma_hit = 0.0;
  const std::string what2 = whatOf([&] { LikelihoodFieldModel model(room(), s); });
  EXPECT_NE(what2.find("laser_sigma_hit"), std::string::npos) << what2;
  s = LikelihoodFieldModelParams();
  s.z_hit = s.z_rand = 0.0;
  EXPECT_THROW(LikelihoodFieldModel(room(), s), std::invalid_argument);
  s = LikelihoodFieldModelParams();
  s.max_distance = -1.0;
  EXPECT_THROW(LikelihoodFieldModel(room(), s), std::invalid_argument);
}

}  // namespace
}  // namespace pf
