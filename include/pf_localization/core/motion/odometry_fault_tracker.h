// The share of particles that assume an odometry fault in the next motion
// update (OdometryMotionParams::fault_fraction: a reversal or a stall instead
// of the odometry's step), adapted to the evidence: the probability of a
// fault given the last scan's likelihood ratio between the faulty particles
// and the others (per particle), with fault_fraction as the prior, clamped to
// [fault_fraction, fault_fraction_max].
//
// Odometry faults come in runs (a robot reverses for a while, wheels spin on
// a threshold for a while), so the last scan's verdict is the best guess of
// how many the next step needs: it rises while a fault lasts and falls back
// to the floor as soon as the odometry is right again, or when the scan
// cannot tell (plain corridor walls).
// A mixture proposal in the sense of Thrun, Fox, Burgard & Dellaert, "Robust
// Monte Carlo localization for mobile robots" (AIJ 128, 2001). See
// docs/design.md, "Odometry faults are observed, not assumed".
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pf_localization/core/motion/odometry_motion_model.h"

namespace pf {

class OdometryFaultTracker {
 public:
  /// Back to the floor, fault_fraction (after an initialisation).
  void restart(const OdometryMotionParams& params) {
    fraction_ = params.fault_fraction;
    along_track_observable_ = true;
  }
  /// Keeps the share within new bounds (the parameters changed).
  void clampTo(const OdometryMotionParams& params);

  /// The share the evidence gives (reported, and what suspect() judges).
  double fraction() const { return fraction_; }
  /// The share the next motion update samples: none while the last scan
  /// could not tell a fault along the direction of travel (see
  /// setAlongTrackObservable), else fraction().
  double sampledFraction() const { return along_track_observable_ ? fraction_ : 0.0; }
  /// Whether the last scan pinned the position along the direction of
  /// travel. Along a featureless corridor it does not: a stalled or reversed
  /// particle fits there as well as the others, so sampling faults would only
  /// grow a tail of particles behind the robot that drags the estimate back.
  /// Odometry then carries the cloud along, as it must.
  void setAlongTrackObservable(bool observable) { along_track_observable_ = observable; }
  /// Whether the faulty particles win (fault_suspect_fraction): the odometry
  /// itself is then in doubt.
  bool suspect(const OdometryMotionParams& params) const {
    return fraction_ >= params.fault_suspect_fraction;
  }
  /// Whether a step of `step` m lets a scan tell faulty particles from the
  /// others. A fault changes the translation by twice its length (reversed)
  /// or by it (stalled): on a step shorter than half fault_margin even a
  /// reversal stays within the stalled particles' own spread, and what
  /// weight the faulty ones win by chance must not grow their share.
  static bool observable(double step, const OdometryMotionParams& params) {
    return 2.0 * step >= params.fault_margin;
  }

  /// Which particles took a fault in the last motion update (1) and which
  /// the odometry's step (0), written by OdometryMotionModel::apply.
  std::vector<uint8_t>* flags() { return &faulty_; }
  /// The new share from the posterior weight of the flagged particles
  /// (`weights` normalised, in the order of the flags) against the share
  /// they were given, clamped; summed on up to `threads` threads (the same
  /// result for any count). After an update that brings a share
  /// `view_share` of a new view (view_share.h), whose weights carry that
  /// share of a scan's evidence, the evidence ratio is taken to the power
  /// 1 / view_share and the memory to the power view_share: a view's worth
  /// of such updates moves the share as one update a view apart does.
  void adapt(const std::vector<double>& weights, const OdometryMotionParams& params,
             int threads = 1, double view_share = 1.0);

  /// Prefaults room for `n` particles' flags.
  void reserve(std::size_t n);

 private:
  double fraction_ = 0.0;
  bool along_track_observable_ = true;
  std::vector<uint8_t> faulty_;
};

}  // namespace pf
