// A lidar covered for a stretch of the run: something stuck over its window
// (a sheet of cardboard, a hand, a jacket dropped on the robot) returns an
// echo from the window itself, so every beam reads range_min, as a real
// lidar reports it, instead of going quiet. The filter sees a sensor that
// keeps publishing at its rate and lies, which is harder to notice than one
// that stops.
//
// The covered readings replace the lidar's own after they were drawn, so the
// random streams, and with them every other scan of the run, stay as they
// would be without the cover.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pf::sim {

struct SensorBlock {
  std::string sensor;   // the lidar's name (PlanarLidar::name)
  int64_t from_ns = 0;  // covered from this stamp (inclusive) ...
  int64_t to_ns = 0;    // ... to this one (exclusive), both after the start of the run

  bool covers(const std::string& name, int64_t t_ns) const {
    return name == sensor && t_ns >= from_ns && t_ns < to_ns;
  }
};

/// Parses "NAME:T0:T1" (seconds after the start of the run, T0 < T1, T0 >= 0).
/// Throws std::invalid_argument naming what is wrong.
SensorBlock parseSensorBlock(const std::string& text);

/// What a covered lidar reads: every one of `beams` beams at range_min.
std::vector<float> coveredReadings(int beams, double range_min);

}  // namespace pf::sim
