// Particles stored as a structure of arrays: the sensor update streams through
// x, y and yaw contiguously, which keeps the hot loop cache-friendly and lets
// the compiler vectorise it.
#pragma once

#include <cstddef>
#include <vector>

#include "pf_localization/core/util/pose2.h"

namespace pf {

struct ParticleSet {
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> yaw;
  std::vector<double> weight;  // normalised: sums to 1 after every update

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }

  void resize(std::size_t n) {
    x.resize(n);
    y.resize(n);
    yaw.resize(n);
    weight.resize(n);
  }

  Pose2 pose(std::size_t i) const { return {x[i], y[i], yaw[i]}; }
  void setPose(std::size_t i, const Pose2& p) {
    x[i] = p.x;
    y[i] = p.y;
    yaw[i] = p.yaw;
  }

  void setUniformWeights() { weight.assign(size(), size() ? 1.0 / size() : 0.0); }
};

}  // namespace pf
