#include "pf_localization/sim/planar_sensor.h"

#include <utility>

namespace pf::sim {

PlanarSensor::PlanarSensor(PlanarLidar lidar, Model model, uint64_t seed,
                           std::vector<SensorBlock> blocks)
    : lidar_(std::move(lidar)), model_(model), random_(seed) {
  safety_.range_min = lidar_.range_min;
  safety_.range_max = lidar_.range_max;
  for (SensorBlock& b : blocks) {
    if (b.sensor == lidar_.name) blocks_.push_back(std::move(b));
  }
}

bool PlanarSensor::coveredAt(int64_t t_ns) const {
  for (const SensorBlock& b : blocks_) {
    if (b.covers(lidar_.name, t_ns)) return true;
  }
  return false;
}

std::vector<float> PlanarSensor::read(const std::vector<double>& ideal, int64_t t_ns) {
  std::vector<float> readings = model_ == Model::kNeato
                                    ? neatoReadings(ideal, neato_, &random_)
                                    : safetyLidarReadings(ideal, safety_, &random_);
  if (coveredAt(t_ns)) return coveredReadings(lidar_.beams, lidar_.range_min);
  return readings;
}

}  // namespace pf::sim
