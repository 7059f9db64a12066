#include "pf_localization/sim/safety_lidar.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pf::sim {

std::vector<float> safetyLidarReadings(const std::vector<double>& ideal,
                                       const SafetyLidarParams& params, SimRandom* random) {
  constexpr float kNoReturn = std::numeric_limits<float>::infinity();
  std::vector<float> out(ideal.size(), kNoReturn);
  for (std::size_t i = 0; i < ideal.size(); ++i) {
    double range = ideal[i];
    // Every beam draws the same numbers whatever it finds, so that a change
    // in one beam's world leaves the noise of the others alone.
    const double short_draw = random->uniform();
    const double short_range = random->uniform(params.range_min, params.range_max);
    const double dropout_draw = random->uniform();
    const double noise = random->gaussian(params.sigma);
    if (short_draw < params.short_rate) range = std::min(range, short_range);
    if (!(range < params.range_max)) continue;
    const double f = range / params.range_max;
    if (dropout_draw < params.dropout_near + (params.dropout_far - params.dropout_near) * f * f) {
      continue;
    }
    range = std::round((range + noise) / params.resolution) * params.resolution;
    if (range >= params.range_max) continue;
    out[i] = static_cast<float>(std::max(range, params.range_min));
  }
  return out;
}

}  // namespace pf::sim
