// Whether a scan runs a filter update, and why not (SkipReason): the input checks (map,
// initialisation, finite odometry, a well-formed scan with a valid beam), the
// odometry-fault check, and the motion thresholds. It keeps the odometry
// pose of the last update, which the motion update starts from.
//
// An update runs only after the robot moved update_min_d or turned
// update_min_a since the last one, as amcl's (Thrun et al., "Probabilistic
// Robotics", 2005, ch. 8) do: a robot standing still would otherwise keep
// multiplying the same evidence into its weights and grow falsely confident.
// It runs at once on the first scan after an initialisation, after
// requestUpdate(), while the odometry is suspect (the faulty particles win),
// and when the scan no longer fits where the odometry says the robot is
// (update_fit_drop): that is when waiting for more odometry costs most. A step
// longer than odom_jump_limit is an odometry fault (a reset, a glitch): it is
// skipped, and tracking resumes from the new odometry pose. See
// docs/design.md, "Updates wait for motion".
#pragma once

#include <optional>
#include <string>

#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/filter/update_gate.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

// Why ParticleFilter::update did not run a filter update: the typed outcome
// that callers branch and rate-limit their logs on, with the specifics of
// each case in UpdateReport::skip_detail.
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

/// The longest step one update makes while the scans come often enough for
/// the gate (odometry_motion_model.h): twice update_min_d and update_min_a.
/// A scan arrives before the robot has gone the threshold again, so an
/// update's step is at most twice it unless the robot moved more than the
/// threshold between two scans. Infinite for a threshold of 0 (every scan
/// updates: nothing says how long an update's step is).
OneUpdateStep oneUpdateStep(const ParticleFilterParams& params);

/// What the gate decided, for the update's report.
struct GateReport {
  SkipReason skip_reason = SkipReason::kNone;  // kNone: the update runs
  std::string skip_detail;                     // the specifics, for the log (may be empty)
  bool fit_dropped = false;  // runs before the thresholds: the scan stopped fitting
  // The beams prepared (when the update runs, and for kNoValidBeam), and
  // those dropped without a reading (those the screening masked not counted).
  int beams_used = 0;
  int beams_dropped = 0;
};

/// What UpdateGate::decide found.
struct GateDecision : GateReport {
  // The odometry at the last update, which the motion update starts from;
  // empty on the first update after an initialisation (no motion then).
  std::optional<Pose2> from;
  double step = 0.0;  // m of odometry travelled since the last update
  // The share of a new view the update brings (view_share.h): of its motion
  // since the last update; 1 for the first, for a requested one and when the
  // fit dropped (the scan changed, whatever the odometry says); while the
  // odometry is suspect, at least leastUpdateShare of the thresholds.
  double view = 1.0;
  // The scans, prepared by the sensor model: when the update runs, and for
  // kNoValidBeam (to count the dropped beams).
  std::optional<std::vector<PreparedScan>> scans;

  bool runs() const { return skip_reason == SkipReason::kNone; }
};

class UpdateGate {
 public:
  /// The next scan that passes the input checks is the first update after an
  /// initialisation: it runs, without motion.
  void restart() { first_pending_ = true; }
  /// The next scan that passes the input checks runs an update, moved or not.
  void requestUpdate() { force_ = true; }

  /// Decides on the scans of one update (one per sensor; one for most
  /// robots). `model` is null without a map; `estimate` is the
  /// last update's, where the fit-drop check predicts the robot from; and
  /// `odometry_suspect` says the faulty particles win (every scan updates).
  /// When the update runs, the gate takes `odom` as the last update's
  /// odometry (and forgets a requested update); on an odometry jump too.
  /// `masked`: the beams of `scans` the screening masked (beam_screen.h),
  /// which the report does not count as dropped.
  GateDecision decide(const Pose2& odom, const ScanGroup& scans, const SensorModel* model,
                      bool initialized, const Pose2& estimate, bool odometry_suspect,
                      const ParticleFilterParams& params, int masked = 0);

  /// Records how well the update's scans fit its estimate: the share of the
  /// beams ending within update_fit_distance of an obstacle, the reference
  /// of the fit-drop check.
  void recordFit(const SensorModel& model, const std::vector<PreparedScan>& scans,
                 const Pose2& estimate, const ParticleFilterParams& params);

  /// Whether an update ran since the last initialisation (restart()).
  bool hasUpdated() const { return !first_pending_ && odom_at_update_.has_value(); }
  /// The odometry pose of the last update (or of the last odometry jump).
  const std::optional<Pose2>& odomAtUpdate() const { return odom_at_update_; }

 private:
  // The scans, prepared, when they fit the pose predicted `since_update`
  // after `estimate` clearly worse than the last update's scans fitted its
  // estimate; nothing otherwise.
  std::optional<std::vector<PreparedScan>> fitDropped(const SensorModel& model,
                                                      const ScanGroup& scans, const Pose2& estimate,
                                                      const Pose2& since_update,
                                                      const ParticleFilterParams& params) const;

  std::optional<Pose2> odom_at_update_;
  bool first_pending_ = false;
  bool force_ = false;
  double fit_at_update_ = 0.0;
};

}  // namespace pf
