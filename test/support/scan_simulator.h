// Test support: laser scans of a grid from a known pose, cast with the
// simulator's exact ray caster (pf::sim::RayCaster: the range to where a beam
// enters the first occupied cell; unknown cells are transparent).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/util/random.h"
#include "pf_localization/sim/ray_caster.h"

namespace pf::test {

/// The laser and its scan: by default 180 beams over a full turn from -pi,
/// 0.05 to 8 m, at the base's centre, taken all at once, without noise.
struct ScanSpec {
  int beams = 180;
  double angle_min = -M_PI;
  double angle_increment = 2.0 * M_PI / 180;
  double range_min = 0.05;
  double range_max = 8.0;
  Pose2 sensor_pose;  // the laser on the base, copied into the scan
  // When each beam is taken while the base moves (copied into the scan):
  // beam i is cast from where the laser is at its own time.
  SweepMotion sweep;
  double noise_sigma = 0.0;  // m, Gaussian noise added to every return
  uint64_t seed = 1;         // of the noise
  // What a beam reads when no occupied cell lies within range_max, or the
  // beam leaves the map first.
  float no_return = std::numeric_limits<float>::quiet_NaN();
};

class ScanSimulator {
 public:
  /// Keeps a copy of the grid.
  explicit ScanSimulator(const OccupancyGrid& grid, const ScanSpec& spec = {});

  const ScanSpec& spec() const { return spec_; }

  /// The scan the laser takes with the base at `base` (at the scan's stamp).
  /// Successive scans draw fresh noise from one seeded generator.
  LaserScan scanFrom(const Pose2& base);

 private:
  // The laser's pose when beam i is taken, in the base frame at the stamp.
  Pose2 laserAtBeam(int i) const;

  sim::RayCaster caster_;
  ScanSpec spec_;
  Random random_;
};

/// A scan of `spec` (its angles, limits, mounting and sweep) in which no
/// beam returns: every range is spec.no_return.
LaserScan noReturnScan(const ScanSpec& spec = {});

/// One scan of `grid` from `base` (a ScanSimulator used once).
LaserScan simulateScan(const OccupancyGrid& grid, const Pose2& base, const ScanSpec& spec = {});

/// A 360-beam scan of `grid` from `base`, a beam a degree, as a Neato's.
LaserScan scan360(const OccupancyGrid& grid, const Pose2& base);

}  // namespace pf::test
