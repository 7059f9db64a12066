#include "pf_localization/core/motion/odometry_fault_tracker.h"

#include <algorithm>
#include <cmath>

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {
namespace {

// The share of the last verdict kept as the next update's prior; the rest
// returns to the floor. 0 forgot a reversal as soon as it was found (the
// faulty particles winning 95 % of the weight gave a share of 0.37).
constexpr double kFaultMemory = 0.5;
// The largest evidence ratio (its log) a partial view's scan is raised to:
// far beyond what moves a posterior, well within a double.
constexpr double kMaxLogRatio = 300.0;

}  // namespace

void OdometryFaultTracker::clampTo(const OdometryMotionParams& params) {
  fraction_ = std::clamp(fraction_, params.fault_fraction, params.fault_fraction_max);
}

void OdometryFaultTracker::adapt(const std::vector<double>& weights,
                                 const OdometryMotionParams& params, int threads,
                                 double view_share) {
  // Without a new view (a robot standing still) the scan says nothing new.
  if (view_share <= 0.0) return;
  const double share = sumBlocks(weights.size(), threads,
                                 [&](std::size_t i) { return faulty_[i] ? weights[i] : 0.0; });
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
  double ratio = (share / prior) / std::max(1e-300, (1.0 - share) / (1.0 - prior));
  // Faults come in runs: the belief before this scan is the last one, half
  // way back to the floor, so that without evidence it decays.
  double memory = kFaultMemory;
  if (view_share < 1.0) {
    // In log space: a tiny share would raise the ratio beyond a double.
    ratio = std::exp(std::clamp(std::log(ratio) / view_share, -kMaxLogRatio, kMaxLogRatio));
    memory = std::pow(kFaultMemory, view_share);
  }
  const double belief = floor + memory * (prior - floor);
  const double posterior = belief * ratio / (belief * ratio + (1.0 - belief));
  fraction_ = std::clamp(posterior, floor, params.fault_fraction_max);
}

void OdometryFaultTracker::reserve(std::size_t n) { prefault(&faulty_, n); }

}  // namespace pf
