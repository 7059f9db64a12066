#include "support/scan_simulator.h"

#include <cmath>

#include "pf_localization/core/motion/scan_deskew.h"

namespace pf::test {

Pose2 ScanSimulator::laserAtBeam(int i) const {
  // Worked out here rather than with sensorPoseAtBeam, which de-skewing
  // uses: a scan drawn by the code under test would agree with it even
  // where both are wrong.
  const SweepMotion& sweep = spec_.sweep;
  const double t = sweep.first_beam_time + i * sweep.time_increment;
  const Pose2& v = sweep.base_velocity;
  if (t == 0.0 || (v.x == 0.0 && v.y == 0.0 && v.yaw == 0.0)) return spec_.sensor_pose;
  return compose(motionOver(v, t), spec_.sensor_pose);
}

ScanSimulator::ScanSimulator(const OccupancyGrid& grid, const ScanSpec& spec)
    : caster_(grid), spec_(spec), random_(spec.seed) {}

LaserScan ScanSimulator::scanFrom(const Pose2& base) {
  LaserScan scan = noReturnScan(spec_);
  for (int i = 0; i < spec_.beams; ++i) {
    const Pose2 laser = compose(base, laserAtBeam(i));
    const double bearing = laser.yaw + spec_.angle_min + i * spec_.angle_increment;
    const double range = caster_.cast(laser.x, laser.y, bearing, spec_.range_max);
    if (std::isfinite(range)) {
      scan.ranges[i] = static_cast<float>(range + random_.gaussian(spec_.noise_sigma));
    }
  }
  return scan;
}

LaserScan noReturnScan(const ScanSpec& spec) {
  LaserScan scan;
  scan.angle_min = spec.angle_min;
  scan.angle_increment = spec.angle_increment;
  scan.range_min = spec.range_min;
  scan.range_max = spec.range_max;
  scan.sensor_pose = spec.sensor_pose;
  scan.sweep = spec.sweep;
  scan.ranges.assign(static_cast<std::size_t>(spec.beams), spec.no_return);
  return scan;
}

LaserScan simulateScan(const OccupancyGrid& grid, const Pose2& base, const ScanSpec& spec) {
  return ScanSimulator(grid, spec).scanFrom(base);
}

LaserScan scan360(const OccupancyGrid& grid, const Pose2& base) {
  ScanSpec spec;
  spec.beams = 360;
  spec.angle_increment = 2.0 * M_PI / 360;
  return simulateScan(grid, base, spec);
}

}  // namespace pf::test
