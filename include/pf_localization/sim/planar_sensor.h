// A planar lidar as pf_simulator runs it: its geometry and schedule
// (planar_lidar.h), the model that turns its ideal ranges into readings (a
// Neato's, ray_caster.h, or a safety lidar's, safety_lidar.h), its own
// random stream, and the stretches of the run it is covered
// (sensor_block.h).
//
// Each sensor draws from its own stream, so that adding a sensor to a rig,
// or covering one, changes nothing in the readings of the others; a covered
// scan draws its readings as usual and then replaces them, so that covering
// a stretch changes that stretch only.
#pragma once

#include <cstdint>
#include <vector>

#include "pf_localization/sim/planar_lidar.h"
#include "pf_localization/sim/ray_caster.h"
#include "pf_localization/sim/safety_lidar.h"
#include "pf_localization/sim/sensor_block.h"
#include "pf_localization/sim/sim_random.h"

namespace pf::sim {

class PlanarSensor {
 public:
  enum class Model { kNeato, kSafety };

  /// The Neato model keeps NeatoLaserParams' defaults, the safety model
  /// SafetyLidarParams' with the lidar's own range limits. `blocks` naming
  /// other sensors are ignored.
  PlanarSensor(PlanarLidar lidar, Model model, uint64_t seed, std::vector<SensorBlock> blocks);

  const PlanarLidar& lidar() const { return lidar_; }

  /// The readings of a scan stamped `t_ns` after the start of the run whose
  /// beams' true ranges are `ideal` (idealRanges): the model's, or range_min
  /// on every beam while a block covers the sensor.
  std::vector<float> read(const std::vector<double>& ideal, int64_t t_ns);

  /// Whether a block covers the sensor at `t_ns`.
  bool coveredAt(int64_t t_ns) const;

 private:
  PlanarLidar lidar_;
  Model model_;
  NeatoLaserParams neato_;
  SafetyLidarParams safety_;
  SimRandom random_;
  std::vector<SensorBlock> blocks_;
};

}  // namespace pf::sim
