// Test helper shared by the ParticleFilter's tests (particle_filter_*_test.cc):
// the rooms they drive in, the laser 0.1 m ahead of the robot, the filter's
// parameters they start from, and a drive tracked with the odometry in a
// frame of its own. Built on test/support's rooms, scans and drives.
#pragma once

#include <cmath>
#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "support/drive_and_track.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace filter_world {

constexpr double kRes = 0.05;

// --- A synthetic world ---------------------------------------------------------

// test/support's rooms: a room of width x height metres in 0.05 m cells, with
// one-cell walls and the given boxes filled.
inline OccupancyGrid room(double width, double height, const std::vector<test::Box>& boxes) {
  return test::room(width, height, kRes, boxes);
}

// The room most tests drive in: 4 m x 3 m, two boxes, nothing symmetric.
using test::asymmetricRoom;

// 360 degrees, 2 degrees apart, from a laser 0.1 m ahead of the robot centre.
inline test::ScanSpec laserAhead() {
  test::ScanSpec spec;
  spec.sensor_pose = {0.1, 0.0, 0.0};
  return spec;
}

// That laser's scan with no return on any beam (180 NaN ranges).
inline LaserScan emptyScan() { return test::noReturnScan(laserAhead()); }

// The exact range to the first occupied cell along each beam, or NaN (no
// return) when the beam leaves the map first.
inline LaserScan simulateScan(const OccupancyGrid& grid, const Pose2& robot) {
  return test::simulateScan(grid, robot, laserAhead());
}

inline ParticleFilterParams baseParams() {
  ParticleFilterParams p;
  p.kld.min_particles = 300;
  p.kld.max_particles = 2000;
  p.seed = 1;
  return p;
}

// With noiseless motion and all particles at one pose, the particles move
// exactly by the odometry and the sensor update cannot change them.
inline ParticleFilterParams exactParams() {
  ParticleFilterParams p = baseParams();
  p.kld.min_particles = 10;
  p.kld.max_particles = 10;
  p.motion.alpha1 = p.motion.alpha2 = p.motion.alpha3 = p.motion.alpha4 = p.motion.alpha5 = 0.0;
  // Nor may recovery: the scans below deliberately disagree with the motion.
  p.recovery.alpha_slow = p.recovery.alpha_fast = 0.0;
  p.recovery.expansion_ratio = 0.0;
  return p;
}

inline Eigen::Matrix3d diag(double sx, double sy, double syaw) {
  return Eigen::Vector3d(sx * sx, sy * sy, syaw * syaw).asDiagonal();
}

inline double distance(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The odometry frame is not the map frame: map -> odom is kOdomInMap.
inline const Pose2 kOdomInMap{0.7, -0.4, 0.3};
inline Pose2 odomOf(const Pose2& truth) { return test::odometryOf(truth, kOdomInMap); }

// Drives `path` with the laser ahead, the odometry in kOdomInMap.
inline test::TrackingRun track(ParticleFilter* filter, const OccupancyGrid& grid,
                               const std::vector<Pose2>& path) {
  test::ScanSimulator scans(grid, laserAhead());
  return test::driveAndTrack(filter, path, &scans, kOdomInMap);
}

// A gently curving drive, 0.25 m per step, starting at (1, 1.5) facing +x.
inline std::vector<Pose2> trackingPath(int steps) {
  return test::stepPath({1.0, 1.5, 0.0}, {0.25, 0.0, 0.05}, steps);
}

}  // namespace filter_world
}  // namespace pf
