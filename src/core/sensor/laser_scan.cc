#include "pf_localization/core/sensor/laser_scan.h"

#include <cmath>

namespace pf {

std::optional<std::string> validateScan(const LaserScan& scan) {
  if (scan.ranges.empty()) return "the scan has no ranges";
  if (!std::isfinite(scan.angle_min)) return "angle_min is not finite";
  if (!std::isfinite(scan.angle_increment) || scan.angle_increment == 0.0) {
    return "angle_increment is zero or not finite (" + std::to_string(scan.angle_increment) + ")";
  }
  if (!std::isfinite(scan.range_max) || !std::isfinite(scan.range_min) ||
      !(scan.range_max > scan.range_min)) {
    return "range_max (" + std::to_string(scan.range_max) +
           ") must be finite and above range_min (" + std::to_string(scan.range_min) + ")";
  }
  if (!scan.sensor_pose.isFinite()) return "the laser's pose on the robot is not finite";
  if (!scan.robot_offset.isFinite()) return "the robot's pose at the scan's stamp is not finite";
  if (!(scan.weight > 0.0 && scan.weight <= 1.0)) {
    return "the sensor's weight (" + std::to_string(scan.weight) + ") is not in (0, 1]";
  }
  if (!std::isfinite(scan.sweep.first_beam_time) || !std::isfinite(scan.sweep.time_increment) ||
      !scan.sweep.base_velocity.isFinite()) {
    return "the sweep's beam times or the robot's velocity during it are not finite";
  }
  return std::nullopt;
}

std::vector<Beam> selectBeams(const LaserScan& scan, int max_beams, double range_min,
                              double range_max, std::size_t* valid_count) {
  const double lo = range_min > 0.0 ? std::max(range_min, scan.range_min) : scan.range_min;
  const double hi = range_max > 0.0 ? std::min(range_max, scan.range_max) : scan.range_max;

  std::vector<Beam> valid;
  valid.reserve(scan.ranges.size());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const float r = scan.ranges[i];
    // A lidar with something stuck over it reads range_min on every beam,
    // and those end points inside the robot would only pull the fit.
    if (isReading(r, lo, hi)) {
      valid.push_back({r, static_cast<float>(scan.angle_min + i * scan.angle_increment), i});
    }
  }
  if (valid_count) *valid_count = valid.size();
  if (max_beams <= 0 || valid.size() <= static_cast<std::size_t>(max_beams)) return valid;

  std::vector<Beam> picked(max_beams);
  for (int k = 0; k < max_beams; ++k) {
    picked[k] = valid[static_cast<std::size_t>(k) * valid.size() / max_beams];
  }
  return picked;
}

}  // namespace pf
