#include "pf_localization/sim/amr_rig.h"

#include <cmath>

namespace pf::sim {

namespace {

constexpr int64_t kMs = 1'000'000;  // ns

PlanarLidar safetyLidar() {
  PlanarLidar l;
  l.height = 0.2;
  l.angle_increment = 0.5 * M_PI / 180.0;
  l.angle_min = -270 * l.angle_increment;  // -135 degrees
  l.beams = 541;
  l.range_min = 0.05;
  l.range_max = 20.0;
  return l;
}

}  // namespace

PlanarLidar amrFrontLidar() {
  PlanarLidar l = safetyLidar();
  l.name = "front";
  l.frame = "front_laser";
  l.topic = "/scan_front";
  l.mount = {0.28, 0.18, M_PI / 4};
  l.schedule = {80 * kMs, 30 * kMs};
  l.scan_time = 0.08;
  return l;
}

PlanarLidar amrRearLidar() {
  PlanarLidar l = safetyLidar();
  l.name = "rear";
  l.frame = "rear_laser";
  l.topic = "/scan_rear";
  l.mount = {-0.28, -0.18, -3 * M_PI / 4};
  l.schedule = {100 * kMs, 60 * kMs};
  l.scan_time = 0.1;
  return l;
}

PlanarLidar amrWarehouseLidar(const ScanSchedule& schedule) {
  PlanarLidar l = safetyLidar();
  l.name = "laser";
  l.frame = "laser";
  l.topic = "/scan";
  l.mount = {0.32, 0.0, 0.0};  // the middle of the front edge
  l.range_max = 25.0;          // a warehouse's long aisles need more than the 20 m
  l.schedule = schedule;
  l.scan_time = 0.1;  // the lidar's own 10 Hz, however sparse the log
  return l;
}

RingLidar amrRingLidar(const ScanSchedule& schedule) {
  RingLidar l;
  l.frame = "velodyne";
  l.mount = {0.0, 0.0, 0.0};
  l.height = 0.6;
  l.schedule = schedule;
  return l;
}

PlanarLidar amrMastLidar(const ScanSchedule& schedule) {
  const RingLidar ring = amrRingLidar(schedule);
  PlanarLidar l;
  l.name = "laser";
  l.frame = "laser";
  l.topic = "/scan";
  l.mount = ring.mount;
  l.height = ring.height;
  l.angle_increment = 0.5 * M_PI / 180.0;
  l.angle_min = 0.0;
  l.beams = 720;
  l.range_min = 0.05;
  l.range_max = 20.0;
  l.schedule = schedule;
  l.scan_time = 0.1;  // a spinning 2D lidar's 10 Hz turn, however sparse the log
  return l;
}

}  // namespace pf::sim
