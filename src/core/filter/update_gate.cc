#include "pf_localization/core/filter/update_gate.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "pf_localization/core/filter/view_share.h"

namespace pf {
namespace {

GateDecision skipped(SkipReason reason, std::string detail = "") {
  GateDecision d;
  d.skip_reason = reason;
  d.skip_detail = std::move(detail);
  return d;
}

// An update's step overshoots the threshold by at most what the robot moves
// between two scans, and the scans come every threshold or more often.
constexpr double kUpdateStepsPerThreshold = 2.0;

}  // namespace

OneUpdateStep oneUpdateStep(const ParticleFilterParams& params) {
  OneUpdateStep step;
  if (params.update_min_d > 0.0) step.distance = kUpdateStepsPerThreshold * params.update_min_d;
  if (params.update_min_a > 0.0) step.angle = kUpdateStepsPerThreshold * params.update_min_a;
  return step;
}

GateDecision UpdateGate::decide(const Pose2& odom, const ScanGroup& scans, const SensorModel* model,
                                bool initialized, const Pose2& estimate, bool odometry_suspect,
                                const ParticleFilterParams& params, int masked) {
  if (!model) return skipped(SkipReason::kNoMap);
  if (!initialized) return skipped(SkipReason::kNotInitialized);
  if (!odom.isFinite()) return skipped(SkipReason::kOdometryNotFinite);
  if (scans.size() == 0) return skipped(SkipReason::kBadScan, "no scan");
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (auto error = validateScan(scans[i])) {
      if (scans.size() > 1) *error = "scan " + std::to_string(i + 1) + " of the group: " + *error;
      return skipped(SkipReason::kBadScan, std::move(*error));
    }
  }

  GateDecision d;
  const bool first = first_pending_ || !odom_at_update_;
  if (!first) {
    const Pose2 delta = between(*odom_at_update_, odom);
    d.step = std::hypot(delta.x, delta.y);
    if (!force_) {
      d.view = newViewShare(delta);
      // While the odometry is suspect every scan is an update, and the
      // motion it shows may be what is wrong: such an update counts at least
      // what the least update the thresholds let through brings (at the
      // defaults, a whole view), so that a run of them cannot use up
      // recovery's patience in a fraction of a view.
      if (odometry_suspect) {
        d.view = std::max(d.view, leastUpdateShare(params.update_min_d, params.update_min_a));
      }
    }
    if (!(d.step <= params.odom_jump_limit)) {
      // Wheels do not carry a robot this far between two scans: moving the
      // particles by it would throw them away.
      odom_at_update_ = odom;
      const double step = d.step;
      d = skipped(SkipReason::kOdometryJumped,
                  std::to_string(d.step) + " m since the last update (odom_jump_limit " +
                      std::to_string(params.odom_jump_limit) +
                      " m): treated as an odometry fault, particles not moved");
      d.step = step;
      return d;
    }
    // While the odometry is suspect, the odometry between updates is what is
    // wrong: every scan updates the filter then, instead of the published
    // pose following the wrong odometry until the robot has "moved"
    // update_min_d.
    if (!force_ && !odometry_suspect && d.step < params.update_min_d &&
        std::fabs(delta.yaw) < params.update_min_a) {
      d.scans = fitDropped(*model, scans, estimate, delta, params);
      if (!d.scans) return skipped(SkipReason::kNotMoved);
      d.fit_dropped = true;
      d.view = 1.0;
    }
  }
  if (!d.scans) d.scans = prepareScans(*model, scans);
  d.beams_used = static_cast<int>(beamCount(*d.scans));
  d.beams_dropped = droppedBeams(*d.scans) - masked;
  if (d.beams_used == 0) {
    // Without evidence the cloud would only be moved; the odometry reference
    // stays, so the motion is applied once a usable scan comes.
    d.skip_reason = SkipReason::kNoValidBeam;
    std::size_t ranges = 0;
    for (const LaserScan& scan : scans) ranges += scan.ranges.size();
    d.skip_detail =
        std::to_string(droppedBeams(*d.scans)) + " of " + std::to_string(ranges) + " beams invalid";
    d.fit_dropped = false;
    return d;
  }
  if (!first) d.from = odom_at_update_;
  odom_at_update_ = odom;
  first_pending_ = false;
  force_ = false;
  return d;
}

void UpdateGate::recordFit(const SensorModel& model, const std::vector<PreparedScan>& scans,
                           const Pose2& estimate, const ParticleFilterParams& params) {
  fit_at_update_ = params.update_fit_drop > 0.0
                       ? hitFraction(model, scans, estimate, params.update_fit_distance)
                       : 0.0;
}

std::optional<std::vector<PreparedScan>> UpdateGate::fitDropped(
    const SensorModel& model, const ScanGroup& scans, const Pose2& estimate,
    const Pose2& since_update, const ParticleFilterParams& params) const {
  if (!(params.update_fit_drop > 0.0)) return std::nullopt;
  std::vector<PreparedScan> prepared = prepareScans(model, scans);
  if (beamCount(prepared) == 0) return std::nullopt;
  const Pose2 predicted = compose(estimate, since_update);
  const double fit = hitFraction(model, prepared, predicted, params.update_fit_distance);
  if (fit >= fit_at_update_ - params.update_fit_drop) return std::nullopt;
  return prepared;
}

const char* toString(SkipReason reason) {
  switch (reason) {
    case SkipReason::kNone:
      return "updated";
    case SkipReason::kNoMap:
      return "no map yet";
    case SkipReason::kNotInitialized:
      return "the filter is not initialised";
    case SkipReason::kOdometryNotFinite:
      return "the odometry pose is not finite";
    case SkipReason::kBadScan:
      return "bad scan";
    case SkipReason::kOdometryJumped:
      return "odometry jumped";
    case SkipReason::kNotMoved:
      return "not moved enough since the last update";
    case SkipReason::kNoValidBeam:
      return "no valid beam in the scan";
  }
  return "unknown skip reason";
}

}  // namespace pf
