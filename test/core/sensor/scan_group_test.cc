// The scans of several sensors in one update (scan_group.h): each placed
// where its sensor was at its stamp, weighed together, fitted together.
#include "pf_localization/core/sensor/scan_group.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/sensor/sensor_update.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

// Two 180-degree lidars on opposite corners of the robot, as an AMR carries
// its safety lidars: each sees one half of the room.
test::ScanSpec frontLidar() {
  test::ScanSpec spec;
  spec.beams = 90;
  spec.angle_min = -M_PI / 2;
  spec.angle_increment = M_PI / 90;
  spec.sensor_pose = {0.25, 0.15, 0.0};
  return spec;
}

test::ScanSpec rearLidar() {
  test::ScanSpec spec = frontLidar();
  spec.sensor_pose = {-0.25, -0.15, M_PI};
  return spec;
}

// The scan `spec`'s lidar took with the robot at `then`, for an update with
// the robot at `now`.
LaserScan scanOf(const OccupancyGrid& grid, const test::ScanSpec& spec, const Pose2& then,
                 const Pose2& now) {
  LaserScan scan = test::simulateScan(grid, then, spec);
  scan.robot_offset = between(now, then);
  return scan;
}

// The largest distance from a mapped obstacle of the end points of `scans`
// placed from `pose`.
double worstEndPoint(const SensorModel& model, const std::vector<PreparedScan>& scans,
                     const Pose2& pose) {
  double worst = 0.0;
  for (const PreparedScan& s : scans) {
    for (std::size_t b = 0; b < s.size(); ++b) {
      const Pose2 end = compose(pose, {s.x[b], s.y[b], 0.0});
      worst = std::max(worst, model.field().distanceAt(end.x, end.y));
    }
  }
  return worst;
}

class ScanGroupTest : public ::testing::Test {
 protected:
  ScanGroupTest() : grid_(test::asymmetricRoom()), model_(grid_, LikelihoodFieldModelParams()) {}

  OccupancyGrid grid_;
  LikelihoodFieldModel model_;
  const Pose2 now_{2.0, 1.5, 0.3};
};

TEST_F(ScanGroupTest, AnEarlierScanStartsWhereItsSensorWas) {
  // The rear lidar's scan is 0.1 s old: the robot was 5 cm back and turned.
  const Pose2 then = compose(now_, {-0.05, 0.0, -0.04});
  std::vector<LaserScan> scans{scanOf(grid_, frontLidar(), now_, now_),
                               scanOf(grid_, rearLidar(), then, now_)};
  const std::vector<PreparedScan> placed = prepareScans(model_, scans, 0);
  ASSERT_EQ(2u, placed.size());
  EXPECT_GT(placed[1].size(), 60u);
  // Every end point on a wall: within the field's quantisation (one cell).
  EXPECT_LE(worstEndPoint(model_, placed, now_), 0.05 + 1e-6);
  // Without the offset the rear scan's end points miss the walls.
  scans[1].robot_offset = {};
  EXPECT_GT(worstEndPoint(model_, prepareScans(model_, scans, 0), now_), 0.3);
  // Where the beams start moved with the robot.
  const Pose2 sensor_then = compose(between(now_, then), rearLidar().sensor_pose);
  EXPECT_NEAR(sensor_then.x, placed[1].sensor_x, 1e-6);
  EXPECT_NEAR(sensor_then.y, placed[1].sensor_y, 1e-6);
}

TEST_F(ScanGroupTest, TheFitTakesEveryScansEndPoints) {
  std::vector<LaserScan> scans{scanOf(grid_, frontLidar(), now_, now_),
                               scanOf(grid_, rearLidar(), now_, now_)};
  const std::vector<PreparedScan> placed = prepareScans(model_, scans, 0);
  const PreparedScan joined = joinedEndPoints(placed);
  EXPECT_EQ(placed[0].size() + placed[1].size(), joined.size());
  EXPECT_EQ(placed[1].x.back(), joined.x.back());
  EXPECT_EQ(placed[0].y.front(), joined.y.front());
  EXPECT_EQ(beamCount(placed), joined.size());
  EXPECT_NEAR(1.0, hitFraction(model_, placed, now_, 0.05 + 1e-6), 1e-12);
  EXPECT_LT(hitFraction(model_, placed, compose(now_, {0.3, 0.0, 0.0}), 0.05), 0.6);
}

TEST_F(ScanGroupTest, TheSensorsLogLikelihoodsAddUpByTheirWeights) {
  std::vector<LaserScan> scans{scanOf(grid_, frontLidar(), now_, now_),
                               scanOf(grid_, rearLidar(), now_, now_)};
  scans[1].weight = 0.5;
  ParticleSet particles;
  particles.resize(3);
  particles.setPose(0, now_);
  particles.setPose(1, compose(now_, {0.1, 0.0, 0.0}));
  particles.setPose(2, compose(now_, {0.0, 0.0, 0.1}));
  for (std::size_t i = 0; i < 3; ++i) particles.weight[i] = 1.0 / 3.0;
  const std::vector<PreparedScan> placed = prepareScans(model_, scans);
  std::vector<double> front, rear;
  model_.logLikelihoods(placed[0], particles, &front);
  model_.logLikelihoods(placed[1], particles, &rear);

  SensorUpdate sensor;
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid_, LikelihoodFieldModelParams()));
  const Weighing w = sensor.weigh(placed, 0.0, 1.0, &particles);
  EXPECT_EQ(1.0, w.tempering);
  // The weights are exp(front + rear / 2), normalised.
  for (std::size_t i = 1; i < 3; ++i) {
    const double expected = (front[i] + 0.5 * rear[i]) - (front[0] + 0.5 * rear[0]);
    EXPECT_NEAR(expected, std::log(particles.weight[i] / particles.weight[0]), 1e-9);
  }
}

TEST_F(ScanGroupTest, ASensorWithoutValidBeamsLeavesTheOthers) {
  // The front lidar covered: every beam at its minimum range reads nothing
  // the filter can use; the rear one carries the update.
  LaserScan covered = test::noReturnScan(frontLidar());
  std::vector<LaserScan> scans{covered, scanOf(grid_, rearLidar(), now_, now_)};
  ParticleFilterParams params;
  params.kld.min_particles = 300;
  params.kld.max_particles = 1000;
  ParticleFilter filter(params);
  filter.setMap(grid_);
  filter.initializeGaussian(now_, Eigen::Vector3d(0.01, 0.01, 0.002).asDiagonal());
  const UpdateReport report = filter.update({}, scans);
  ASSERT_TRUE(report.updated) << skipMessage(report);
  EXPECT_EQ(static_cast<int>(prepareScans(model_, scans)[1].size()), report.beams_used);
}

TEST_F(ScanGroupTest, ABadScanInAGroupIsNamed) {
  std::vector<LaserScan> scans{scanOf(grid_, frontLidar(), now_, now_),
                               scanOf(grid_, rearLidar(), now_, now_)};
  scans[1].weight = 0.0;
  ParticleFilter filter(ParticleFilterParams{});
  filter.setMap(grid_);
  filter.initializeGaussian(now_, Eigen::Vector3d(0.01, 0.01, 0.002).asDiagonal());
  UpdateReport report = filter.update({}, scans);
  EXPECT_EQ(SkipReason::kBadScan, report.skip_reason);
  EXPECT_NE(std::string::npos, report.skip_detail.find("scan 2 of the group"))
      << report.skip_detail;
  EXPECT_NE(std::string::npos, report.skip_detail.find("weight")) << report.skip_detail;
  scans[1].weight = 1.0;
  scans[1].robot_offset.x = std::nan("");
  report = filter.update({}, scans);
  EXPECT_EQ(SkipReason::kBadScan, report.skip_reason);
  EXPECT_NE(std::string::npos, report.skip_detail.find("not finite")) << report.skip_detail;
}

// How the rear lidar's scans reach the filter in trackingRms.
enum class Rear {
  kSameTime,        // taken at the front one's stamp
  kEarlier,         // a step (50 ms) earlier, placed by robot_offset
  kEarlierAsIfNow,  // a step earlier, placed as if taken at the update
  kNone,            // not at all: the front lidar alone
};

// The position RMSE of a filter tracking a robot that drives a 1 m circle
// in the room, 5 cm and 0.05 rad per scan, after the first 20 scans.
double trackingRms(const OccupancyGrid& grid, Rear rear) {
  ParticleFilterParams params;
  params.kld.min_particles = 300;
  params.kld.max_particles = 2000;
  params.seed = 3;
  ParticleFilter filter(params);
  filter.setMap(grid);
  Pose2 truth{1.0, 1.0, 0.0};
  filter.initializeGaussian(truth, Eigen::Vector3d(0.01, 0.01, 0.003).asDiagonal());
  const Pose2 step{0.05, 0.0, 0.05};
  double sum = 0.0;
  int n = 0;
  for (int i = 0; i < 120; ++i) {
    const Pose2 before = truth;
    truth = compose(truth, step);
    std::vector<LaserScan> scans{scanOf(grid, frontLidar(), truth, truth)};
    if (rear == Rear::kSameTime) scans.push_back(scanOf(grid, rearLidar(), truth, truth));
    if (rear == Rear::kEarlier) scans.push_back(scanOf(grid, rearLidar(), before, truth));
    if (rear == Rear::kEarlierAsIfNow) scans.push_back(scanOf(grid, rearLidar(), before, before));
    // The odometry is the truth: map -> odom is the identity.
    const UpdateReport report = filter.update(truth, scans);
    if (i >= 20 && report.updated) {
      const Pose2 e = filter.estimate().pose;
      sum += (e.x - truth.x) * (e.x - truth.x) + (e.y - truth.y) * (e.y - truth.y);
      ++n;
    }
  }
  return std::sqrt(sum / std::max(n, 1));
}

// Two half views score as one full view, even when the sensors' scans are
// not taken at the same time, as long as each is placed where it was taken.
TEST_F(ScanGroupTest, TwoHalfViewsTrackTheRobot) {
  const double same_time = trackingRms(grid_, Rear::kSameTime);
  const double earlier = trackingRms(grid_, Rear::kEarlier);
  EXPECT_LT(same_time, 0.03);
  EXPECT_LT(earlier, 1.2 * same_time);
  EXPECT_GT(trackingRms(grid_, Rear::kEarlierAsIfNow), 1.2 * earlier);
  EXPECT_GT(trackingRms(grid_, Rear::kNone), 1.2 * earlier);
}

}  // namespace
}  // namespace pf
