#include "pf_localization/core/odometry_fault_tracker.h"

#include <algorithm>

#include "pf_localization/core/prefault.h"

namespace pf {

void OdometryFaultTracker::clampTo(const OdometryMotionParams& params) {
  fraction_ = std::clamp(fraction_, params.fault_fraction, params.fault_fraction_max);
}

void OdometryFaultTracker::adapt(const std::vector<double>& weights,
                                 const OdometryMotionParams& params) {
  // In a corridor, where the scans cannot tell the faulty particles from the
  // others, their share stays where it was put: at the floor.
  double share = 0.0;
  for (std::size_t i = 0; i < weights.size(); ++i) share += faulty_[i] ? weights[i] : 0.0;
  fraction_ = std::clamp(share, params.fault_fraction, params.fault_fraction_max);
}

void OdometryFaultTracker::reserve(std::size_t n) { prefault(&faulty_, n); }

}  // namespace pf
