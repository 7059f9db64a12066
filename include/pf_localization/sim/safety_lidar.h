// The readings of an industrial safety lidar (the 270-degree scanners an AMR
// carries front and rear) for ideal ranges.
//
// Such a lidar is far cleaner than a Neato's: no blind sectors (it sits on
// the robot's corner with nothing in its field of view), centimetre-level
// Gaussian noise, millimetre resolution, and only a few dropouts, more of
// them at long range where the echo is weak. A beam without a return
// (nothing within range_max, or a dropout) reads +inf, as REP 117 asks of
// drivers ("no return" is not a measurement at range_max); a return nearer
// than range_min reads range_min, which is also what a lidar with something
// stuck over its window reports on every beam (sensor_block.h).
#pragma once

#include <vector>

#include "pf_localization/sim/sim_random.h"

namespace pf::sim {

struct SafetyLidarParams {
  double range_min = 0.05;      // m
  double range_max = 20.0;      // m; a return at or beyond it reads +inf
  double sigma = 0.01;          // m, Gaussian range noise
  double resolution = 0.001;    // m, readings are rounded to this
  double dropout_near = 0.002;  // probability of a dropout at range 0
  double dropout_far = 0.03;    // ... at range_max (quadratic in between)
  double short_rate = 0.001;    // probability of a random short return (dust, a glint)
};

/// Readings for ideal ranges (+inf: nothing there), beam by beam.
std::vector<float> safetyLidarReadings(const std::vector<double>& ideal,
                                       const SafetyLidarParams& params, SimRandom* random);

}  // namespace pf::sim
