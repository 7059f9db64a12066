// A planar (2D) lidar on the simulated robot: where it is mounted, when it
// scans, the directions of its beams, and the ideal ranges they find.
//
// A scan is taken in an instant: every beam is cast from the sensor's true
// pose at the scan's stamp (the message's time_increment is 0), so a consumer
// that projects each beam from where tf says the sensor was at the stamp gets
// the geometry exactly. Beam i points along the sensor-frame angle
// angle_min + i * angle_increment, counterclockwise from the sensor's x axis,
// as in sensor_msgs/LaserScan.
#pragma once

#include <string>
#include <vector>

#include "pf_localization/core/util/pose2.h"
#include "pf_localization/sim/path_script.h"
#include "pf_localization/sim/ray_caster.h"
#include "pf_localization/sim/scan_schedule.h"
#include "pf_localization/sim/scene_3d.h"

namespace pf::sim {

struct PlanarLidar {
  std::string name;              // how options name it (pf_simulator --block NAME:T0:T1)
  std::string frame;             // its tf frame
  std::string topic;             // where its scans are published
  Pose2 mount;                   // base_link -> frame
  double height = 0.0;           // m, frame above base_link (on /tf only: the world is planar)
  double angle_min = 0.0;        // rad, sensor frame, the first beam
  double angle_increment = 0.0;  // rad
  int beams = 0;
  double range_min = 0.0, range_max = 0.0;  // m
  ScanSchedule schedule;
  double scan_time = 0.0;  // s one scan takes (the message's scan_time): the
                           // period, unless a log keeps only some scans

  /// The sensor-frame angle of the last beam.
  double angleMax() const { return angle_min + (beams - 1) * angle_increment; }
  /// The sensor's pose in the map when base_link is at `base`.
  Pose2 poseIn(const Pose2& base) const { return compose(base, mount); }
};

/// The true range of every beam of `lidar` with base_link at `base` (map
/// frame), `t` seconds into the run: to the first wall within range_max
/// (+inf when there is none) or to a nearer person (possibly beyond
/// range_max; the reading models make anything there "no return").
std::vector<double> idealRanges(const PlanarLidar& lidar, const RayCaster& walls,
                                const std::vector<Person>& people, const Pose2& base, double t);

/// The same in a 3D world: every beam cast level from `lidar.height` above
/// the floor, to whatever the scene holds at that height (+inf: nothing
/// within range_max).
std::vector<double> idealRanges(const PlanarLidar& lidar, const Scene3D& scene, const Pose2& base,
                                double t);

}  // namespace pf::sim
