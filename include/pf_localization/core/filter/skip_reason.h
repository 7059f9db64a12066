// Why ParticleFilter::update did not run a filter update: the typed outcome
// that callers branch and rate-limit their logs on, with the specifics of
// each case in UpdateReport::skip_detail.
#pragma once

namespace pf {

enum class SkipReason {
  kNone,               // the update ran
  kNoMap,              // no map installed yet
  kNotInitialized,     // no particles: neither initializeGaussian nor initializeUniform ran
  kOdometryNotFinite,  // the odometry pose has a NaN or an infinity
  kBadScan,            // the scan is malformed (validateScan): the detail says how
  kOdometryJumped,     // further than odom_jump_limit since the last update: an odometry fault
  kNotMoved,           // below update_min_d and update_min_a, and the scan still fits
  kNoValidBeam,        // no beam of the scan is usable
};

/// A few words for `reason`, e.g. "not moved enough since the last update".
const char* toString(SkipReason reason);

}  // namespace pf
