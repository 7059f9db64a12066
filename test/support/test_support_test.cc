// The test support itself: the worlds are what they say, the scans are the
// exact ranges, and driveAndTrack reports the filter's real errors.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "support/drive_and_track.h"
#include "support/grid_from_rows.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf::test {
namespace {

TEST(GridFromRows, TheTopRowIsTheHighestAndEveryCellKeepsItsState) {
  const OccupancyGrid grid = gridFromRows({"#..", "..?"}, 0.5, {1.0, 2.0, 0.0});
  ASSERT_EQ(3, grid.width());
  ASSERT_EQ(2, grid.height());
  EXPECT_EQ(0.5, grid.resolution());
  EXPECT_EQ(CellState::kOccupied, grid.state({0, 1}));
  EXPECT_EQ(CellState::kFree, grid.state({0, 0}));
  EXPECT_EQ(CellState::kUnknown, grid.state({2, 0}));
  // The origin places cell (0, 1) at x in [1, 1.5), y in [2.5, 3).
  EXPECT_EQ(CellState::kOccupied, grid.state(grid.worldToCell(1.2, 2.7)));
  EXPECT_THROW(gridFromRows({"##", "#"}, 0.1), std::invalid_argument);
  EXPECT_THROW(gridFromRows({"#x"}, 0.1), std::invalid_argument);
  EXPECT_THROW(gridFromRows({}, 0.1), std::invalid_argument);
}

TEST(Rooms, WallsOnTheBorderAndBoxesByCellCentre) {
  const OccupancyGrid grid = room(1.0, 0.6, 0.1, {{0.5, 0.2, 0.6, 0.4}});
  ASSERT_EQ(10, grid.width());
  ASSERT_EQ(6, grid.height());
  int occupied = 0;
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 10; ++x) occupied += grid.state({x, y}) == CellState::kOccupied;
  }
  EXPECT_EQ(2 * 10 + 2 * 4 + 2, occupied);  // the border and cells (5, 2), (5, 3)
  EXPECT_EQ(CellState::kOccupied, grid.state({5, 2}));
  EXPECT_EQ(CellState::kOccupied, grid.state({5, 3}));
  EXPECT_EQ(CellState::kFree, grid.state({4, 2}));
  const OccupancyGrid asymmetric = asymmetricRoom();
  ASSERT_EQ(80, asymmetric.width());
  ASSERT_EQ(60, asymmetric.height());
  EXPECT_EQ(CellState::kOccupied, asymmetric.state(asymmetric.worldToCell(2.75, 0.85)));
  EXPECT_EQ(CellState::kOccupied, asymmetric.state(asymmetric.worldToCell(0.8, 2.2)));
  EXPECT_EQ(CellState::kFree, asymmetric.state(asymmetric.worldToCell(0.8, 0.85)));
  EXPECT_EQ(CellState::kFree, asymmetric.state(asymmetric.worldToCell(2.75, 2.2)));
  const OccupancyGrid wall = wallGrid(8);
  EXPECT_EQ(CellState::kOccupied, wall.state({8, 4}));
  EXPECT_EQ(CellState::kFree, wall.state({7, 4}));
  EXPECT_EQ(CellState::kFree, wall.state({9, 0}));
}

TEST(ScanSimulator, ExactRangesFromTheMountedLaser) {
  ScanSpec spec;
  spec.beams = 4;
  spec.angle_min = 0.0;
  spec.angle_increment = M_PI / 2;
  spec.range_max = 4.0;
  spec.sensor_pose = {0.1, 0.0, 0.0};
  // From (0.15, 0.25) the laser sits at x = 0.25: the wall is entered 0.55 m
  // ahead; up, down and back the beams leave the map.
  const LaserScan scan = simulateScan(wallGrid(8), {0.15, 0.25, 0.0}, spec);
  ASSERT_EQ(4u, scan.ranges.size());
  EXPECT_NEAR(0.55, scan.ranges[0], 1e-6);
  EXPECT_TRUE(std::isnan(scan.ranges[1]));
  EXPECT_TRUE(std::isnan(scan.ranges[2]));
  EXPECT_EQ(0.1, scan.sensor_pose.x);
  EXPECT_EQ(4.0, scan.range_max);
  // A wall beyond range_max is no return either.
  spec.range_max = 0.5;
  spec.no_return = 0.0f;
  EXPECT_EQ(0.0f, simulateScan(wallGrid(8), {0.15, 0.25, 0.0}, spec).ranges[0]);
}

TEST(ScanSimulator, ANoReturnScanHasTheSpecsLayoutAndNoRange) {
  ScanSpec spec;
  spec.beams = 7;
  spec.angle_min = -0.3;
  spec.sensor_pose = {0.2, 0.0, 0.1};
  spec.sweep.time_increment = 0.01;
  LaserScan scan = noReturnScan(spec);
  ASSERT_EQ(7u, scan.ranges.size());
  for (float range : scan.ranges) EXPECT_TRUE(std::isnan(range));
  EXPECT_EQ(-0.3, scan.angle_min);
  EXPECT_EQ(0.2, scan.sensor_pose.x);
  EXPECT_EQ(0.01, scan.sweep.time_increment);
  spec.no_return = 0.0f;
  scan = noReturnScan(spec);
  for (float range : scan.ranges) EXPECT_EQ(0.0f, range);
}

TEST(ScanSimulator, SeededNoiseOfTheGivenSpread) {
  ScanSpec spec;
  spec.beams = 2000;
  spec.angle_min = -0.5;
  spec.angle_increment = 1.0 / 2000;
  spec.noise_sigma = 0.02;
  spec.seed = 5;
  const OccupancyGrid grid = room(4.0, 3.0, 0.05);
  ScanSimulator noisy(grid, spec);
  const LaserScan a = noisy.scanFrom({2.0, 1.5, 0.0});
  const LaserScan b = noisy.scanFrom({2.0, 1.5, 0.0});
  EXPECT_NE(a.ranges, b.ranges);  // fresh noise each scan
  EXPECT_EQ(a.ranges, ScanSimulator(grid, spec).scanFrom({2.0, 1.5, 0.0}).ranges);  // same seed
  // Against the noiseless caster: about zero mean and 2 cm spread.
  spec.noise_sigma = 0.0;
  const LaserScan ideal = simulateScan(grid, {2.0, 1.5, 0.0}, spec);
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t i = 0; i < a.ranges.size(); ++i) {
    const double e = a.ranges[i] - ideal.ranges[i];
    sum += e;
    sum2 += e * e;
  }
  const double n = static_cast<double>(a.ranges.size());
  EXPECT_NEAR(0.0, sum / n, 0.002);
  EXPECT_NEAR(0.02, std::sqrt(sum2 / n), 0.002);
}

TEST(ScanSimulator, EachBeamIsCastFromWhereTheSweepHasCarriedTheLaser) {
  // Turning on the spot at pi/2 rad/s in a 0.1 m cell room, beams 1 s apart,
  // stamped at the first: beam 1 points along laser-frame pi/2 but, a quarter
  // turn later, ends up pointing along world pi, beam 2 along world 2 pi.
  ScanSpec spec;
  spec.beams = 3;
  spec.angle_min = 0.0;
  spec.angle_increment = M_PI / 2;
  spec.sweep.time_increment = 1.0;
  spec.sweep.base_velocity = {0.0, 0.0, M_PI / 2};
  const OccupancyGrid grid = room(4.0, 2.0, 0.1);  // inner faces at x 0.1, 3.9; y 0.1, 1.9
  const LaserScan scan = simulateScan(grid, {1.0, 1.0, 0.0}, spec);
  EXPECT_NEAR(2.9, scan.ranges[0], 1e-6);  // +x
  EXPECT_NEAR(0.9, scan.ranges[1], 1e-6);  // -x
  EXPECT_NEAR(2.9, scan.ranges[2], 1e-6);  // +x again
  EXPECT_EQ(1.0, scan.sweep.time_increment);
}

TEST(DriveAndTrack, PathsOfSeveralLegsAndTheOdometryOfAFrame) {
  std::vector<Pose2> path{{1.0, 0.0, 0.0}};
  driveOn(&path, {0.5, 0.0, 0.0}, 2);
  driveOn(&path, {0.0, 0.0, M_PI / 2}, 1);
  driveOn(&path, {0.5, 0.0, 0.0}, 1);
  ASSERT_EQ(5u, path.size());
  EXPECT_NEAR(2.0, path[3].x, 1e-12);
  EXPECT_NEAR(M_PI / 2, path[3].yaw, 1e-12);
  EXPECT_NEAR(0.5, path[4].y, 1e-12);
  // Odometry in a frame 1 m along x and a quarter turn from the map's.
  const Pose2 odom_in_map{1.0, 0.0, M_PI / 2};
  const Pose2 odom = odometryOf({1.0, 2.0, M_PI / 2}, odom_in_map);
  EXPECT_NEAR(2.0, odom.x, 1e-12);
  EXPECT_NEAR(0.0, odom.y, 1e-12);
  EXPECT_NEAR(0.0, odom.yaw, 1e-12);
}

TEST(DriveAndTrack, SettledAtIsWhereTheErrorsStayWithinTheLimits) {
  TrackingRun run;
  for (double error : {0.5, 0.1, 0.3, 0.1, 0.05, 0.1}) {
    TrackedStep step;
    step.position_error = error;
    step.yaw_error = error / 10.0;
    run.steps.push_back(step);
  }
  EXPECT_EQ(3, run.settledAt(0.2, 0.2));  // not at 1: step 2 is off again
  EXPECT_EQ(0, run.settledAt(1.0, 1.0));
  EXPECT_EQ(-1, run.settledAt(0.08, 1.0));   // the last is off
  EXPECT_EQ(-1, run.settledAt(1.0, 0.008));  // by its yaw, 0.01
  EXPECT_EQ(0.5, run.maxPositionError());
  EXPECT_EQ(0.1, run.maxPositionError(3));
}

TEST(DriveAndTrack, ReportsTheErrorsOfAFilterThatTracks) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params;
  params.kld.min_particles = 300;
  params.kld.max_particles = 2000;
  params.seed = 1;
  // The cloud's own convergence: a scan fit would put the first estimate on
  // the truth already.
  params.refine_estimate = false;
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeGaussian({1.18, 1.26, 0.1},
                            Eigen::Vector3d(0.09, 0.09, 0.0225).asDiagonal().toDenseMatrix());
  ScanSpec spec;
  spec.sensor_pose = {0.1, 0.0, 0.0};
  ScanSimulator scans(grid, spec);
  const std::vector<Pose2> path = stepPath({1.0, 1.5, 0.0}, {0.25, 0.0, 0.05}, 10);
  ASSERT_EQ(11u, path.size());
  EXPECT_NEAR(1.25, path[1].x, 1e-12);
  const Pose2 odom_in_map{0.7, -0.4, 0.3};
  const TrackingRun run = driveAndTrack(&filter, path, &scans, odom_in_map);
  ASSERT_EQ(path.size(), run.steps.size());
  for (const TrackedStep& step : run.steps) ASSERT_TRUE(step.report.updated);
  // Off by 0.3 m at the start, within 0.1 m and 0.05 rad at the end.
  EXPECT_GT(run.steps[0].position_error, run.last().position_error);
  EXPECT_LT(run.last().position_error, 0.1);
  EXPECT_LT(run.last().yaw_error, 0.05);
  EXPECT_GE(run.maxPositionError(), run.last().position_error);
  EXPECT_NEAR(
      std::hypot(run.last().estimate.x - path.back().x, run.last().estimate.y - path.back().y),
      run.last().position_error, 1e-12);
  // The odometry it was fed is in the frame given: map -> odom recovers it.
  const Pose2 map_to_odom = *filter.mapToOdom();
  EXPECT_LT(std::hypot(map_to_odom.x - odom_in_map.x, map_to_odom.y - odom_in_map.y), 0.15);
}

}  // namespace
}  // namespace pf::test
