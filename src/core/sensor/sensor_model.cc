#include "pf_localization/core/sensor/sensor_model.h"

#include <algorithm>
#include <cmath>

namespace pf {

PreparedScan prepareScan(const LaserScan& scan, int max_beams, double range_min, double range_max,
                         double resolution) {
  std::size_t valid = 0;
  const std::vector<Beam> beams = selectBeams(scan, max_beams, range_min, range_max, &valid);
  PreparedScan out;
  out.range_max = scoredRangeMax(scan.range_max, range_max);
  out.dropped = static_cast<int>(scan.ranges.size() - valid);
  out.weight = scan.weight;
  // A scan of another sensor taken before the update: every beam from where
  // the robot was then (scan_group.h).
  const bool offset = !scan.robot_offset.isIdentity();
  const Pose2 sensor = offset ? compose(scan.robot_offset, scan.sensor_pose) : scan.sensor_pose;
  out.sensor_x = sensor.x;
  out.sensor_y = sensor.y;
  out.x.reserve(beams.size());
  out.y.reserve(beams.size());
  out.range.reserve(beams.size());
  out.angle.reserve(beams.size());
  const bool skewed = !scan.sweep.isStill();
  for (const Beam& b : beams) {
    const Pose2 at_beam =
        skewed ? sensorPoseAtBeam(scan.sensor_pose, scan.sweep, b.index) : scan.sensor_pose;
    const Pose2 from = offset ? compose(scan.robot_offset, at_beam) : at_beam;
    const Pose2 end =
        compose(from, {b.range * std::cos(b.bearing), b.range * std::sin(b.bearing), 0.0});
    // Ranges of 1e38 m pass the scan's own limits when range_max is absurd;
    // in float cells they overflow, so they are dropped like any bad beam.
    if (!std::isfinite(static_cast<float>(end.x / resolution)) ||
        !std::isfinite(static_cast<float>(end.y / resolution))) {
      ++out.dropped;
      continue;
    }
    out.x.push_back(static_cast<float>(end.x));
    out.y.push_back(static_cast<float>(end.y));
    if (skewed) {
      // The beam model casts every ray from the sensor's reference position:
      // the moved beam becomes the ray from there to its de-skewed end point.
      const double dx = end.x - sensor.x, dy = end.y - sensor.y;
      out.range.push_back(static_cast<float>(std::hypot(dx, dy)));
      out.angle.push_back(static_cast<float>(std::atan2(dy, dx)));
    } else {
      out.range.push_back(b.range);
      out.angle.push_back(static_cast<float>(normalizeAngle(sensor.yaw + b.bearing)));
    }
  }
  return out;
}

double SensorModel::hitFraction(const PreparedScan& scan, const Pose2& pose,
                                double distance) const {
  if (scan.size() == 0) return 0.0;
  std::size_t hits = 0;
  for (std::size_t b = 0; b < scan.size(); ++b) {
    const Pose2 end = compose(pose, {scan.x[b], scan.y[b], 0.0});
    hits += field().distanceAt(end.x, end.y) <= distance ? 1 : 0;
  }
  return static_cast<double>(hits) / static_cast<double>(scan.size());
}

}  // namespace pf
