// The small AMR that pf_simulator drives for its multi-sensor rigs, and the
// sensors it carries, with the mountings of a typical industrial AMR.
//
// The body is 0.64 x 0.44 m. As on most small AMRs, the two 270-degree
// safety lidars sit on diagonally opposite corners, each looking out of its
// corner, so that neither sees the robot's own body and together they see
// all around it; each alone misses the quarter behind its corner:
//
//          y
//          ^      front_laser (0.28, 0.18), yaw +45 deg, 12.5 Hz
//     +----|---[F]
//     |    |     |  -> x (forward)
//     [R]--------+
//     rear_laser (-0.28, -0.18), yaw -135 deg, 10 Hz
//
// Both are 0.2 m above the floor, 541 beams at 0.5 degrees from -135 to
// +135 degrees, 0.05-20 m. Their scans are never stamped at the same instant
// (12.5 Hz from 30 ms, 10 Hz from 60 ms: one is on odd 10 ms ticks, the
// other on even ones).
//
// The warehouse rig keeps the body and carries one safety lidar
// of longer range, centred on the front edge, as a warehouse AMR that only
// drives forwards does: 0.2 m up, 541 beams at 0.5 degrees from -135 to +135
// degrees, 0.05-25 m, 10 Hz (or a log's sparser period). Its 270 degrees
// miss the quarter behind the robot.
//
// The 3D rig puts a 16-ring lidar (ring_lidar.h) on a mast above the centre
// of the robot, 0.6 m up, and a 360-degree planar lidar at the same place,
// for comparing the two on the same path.
#pragma once

#include "pf_localization/sim/planar_lidar.h"
#include "pf_localization/sim/ring_lidar.h"

namespace pf::sim {

/// The radius of the circle around the AMR's body (what checkClearance keeps
/// out of the walls): half its diagonal, rounded up.
inline constexpr double kAmrRadius = 0.39;

/// The front-left safety lidar: name "front", frame front_laser, /scan_front.
PlanarLidar amrFrontLidar();
/// The rear-right safety lidar: name "rear", frame rear_laser, /scan_rear.
PlanarLidar amrRearLidar();

/// The warehouse rig's front lidar: name "laser", frame laser (x 0.32, y 0,
/// z 0.2, yaw 0), /scan, range 0.05-25 m, scanning on `schedule`.
PlanarLidar amrWarehouseLidar(const ScanSchedule& schedule);

/// The 3D rig's 16-ring lidar: frame velodyne, 0.6 m above base_link's
/// origin, yaw 0, sweeping on `schedule`.
RingLidar amrRingLidar(const ScanSchedule& schedule);
/// The 3D rig's planar lidar at the ring lidar's place: name "laser", frame
/// laser, /scan, 720 beams at 0.5 degrees all around from angle 0,
/// 0.05-20 m, scanning with the ring lidar (same schedule).
PlanarLidar amrMastLidar(const ScanSchedule& schedule);

}  // namespace pf::sim
