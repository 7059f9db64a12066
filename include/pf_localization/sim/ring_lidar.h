// A 16-ring spinning 3D lidar (the geometry of a Velodyne VLP-16) in the
// simulated 3D world (scene_3d.h), and its sweeps as organized point clouds.
//
// Ring r (0 the lowest) looks up at min_elevation + r * (max_elevation -
// min_elevation) / (rings - 1): -15 to +15 degrees in 2 degree steps.
// Column c looks along the sensor-frame azimuth c * 360 / columns degrees,
// counterclockwise from the sensor's x axis: 1800 columns, 0.2 degrees
// apart. A sweep is taken in an instant, every ray from the sensor's true
// pose at the stamp (the sensor stays level: the robot drives on a flat
// floor). Point (r, c) is element r * columns + c, in the sensor frame, as
// in a PointCloud2 of height `rings` and width `columns`; a ray without a
// return (nothing within range_max, a dropout, or a return nearer than
// range_min) is NaN in x, y and z.
//
// Ranges get Gaussian noise (the VLP-16's +-3 cm accuracy) and a few
// dropouts. The intensity is the reflectivity of what was hit, one value
// per kind of surface (floor 10, ceiling 30, walls 60, objects 100,
// people 40; 0 without a return): enough to tell them apart in rviz, and
// cheap to store.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "pf_localization/core/util/pose2.h"
#include "pf_localization/sim/scan_schedule.h"
#include "pf_localization/sim/scene_3d.h"
#include "pf_localization/sim/sim_random.h"

namespace pf::sim {

struct RingLidar {
  std::string frame;
  Pose2 mount;          // base_link -> frame, level
  double height = 0.0;  // m, frame above base_link (base_link is on the floor)
  int rings = 16;
  double min_elevation = -15.0 * M_PI / 180.0;
  double max_elevation = 15.0 * M_PI / 180.0;
  int columns = 1800;
  double range_min = 0.5, range_max = 100.0;  // m
  double sigma = 0.015;                       // m, Gaussian range noise
  double dropout = 0.003;                     // probability that a ray returns nothing
  ScanSchedule schedule{100'000'000, 0};      // 10 Hz

  double elevation(int ring) const {
    return min_elevation + ring * (max_elevation - min_elevation) / (rings - 1);
  }
  double azimuth(int column) const { return column * (2.0 * M_PI / columns); }
};

struct RingPoint {
  float x, y, z;  // m, sensor frame; NaN without a return
  float intensity;
};

/// One sweep of `lidar` with base_link at `base` (map frame), `t` seconds
/// into the run: rings * columns points, ring by ring.
std::vector<RingPoint> ringSweep(const RingLidar& lidar, const Scene3D& scene, const Pose2& base,
                                 double t, SimRandom* random);

/// The intensity a sweep gives a point on `surface`.
float surfaceIntensity(Surface surface);

}  // namespace pf::sim
