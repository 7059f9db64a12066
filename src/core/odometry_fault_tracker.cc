#include "pf_localization/core/odometry_fault_tracker.h"

#include <algorithm>

#include "pf_localization/core/prefault.h"

namespace pf {

void OdometryFaultTracker::clampTo(const OdometryMotionParams& params) {
  fraction_ = std::clamp(fraction_, params.fault_fraction, params.fault_fraction_max);
}

void OdometryFaultTracker::adapt(const std::vector<double>& weights,
                                 const OdometryMotionParams& params) {
  double share = 0.0;
  for (std::size_t i = 0; i < weights.size(); ++i) share += faulty_[i] ? weights[i] : 0.0;
  // The scan's evidence for a fault: how much more weight per particle the
  // faulty ones won than the others, against the share they were given.
  // Where the scan cannot tell them apart (plain corridor walls) the ratio
  // is 1 and the share falls back to the floor; taking the won share itself
  // would let chance lift it, step after step, to fault_fraction_max.
  const double prior = fraction_, floor = params.fault_fraction;
  if (prior <= 0.0 || prior >= 1.0 || floor <= 0.0) {
    fraction_ = std::clamp(share, floor, params.fault_fraction_max);
    return;
  }
  const double ratio = (share / prior) / std::max(1e-300, (1.0 - share) / (1.0 - prior));
  const double posterior = floor * ratio / (floor * ratio + (1.0 - floor));
  fraction_ = std::clamp(posterior, floor, params.fault_fraction_max);
}

void OdometryFaultTracker::reserve(std::size_t n) { prefault(&faulty_, n); }

}  // namespace pf
