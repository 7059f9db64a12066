// The motion step of the filter update: the odometry motion model
// (odometry_motion_model.h: Thrun et al., "Probabilistic Robotics", table
// 5.6, with odometry faults), run with the fault share that
// OdometryFaultTracker adapts from scan to scan.
#pragma once

#include <cstddef>
#include <vector>

#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/motion/odometry_fault_tracker.h"
#include "pf_localization/core/motion/odometry_motion_model.h"
#include "pf_localization/core/util/random.h"

namespace pf {

class MotionUpdate {
 public:
  /// Throws std::invalid_argument as OdometryMotionModel does.
  MotionUpdate(const OdometryMotionParams& params, const OneUpdateStep& update_step)
      : model_(params, update_step) {}

  /// Replaces the model (new parameters); the fault share is kept within
  /// the new bounds.
  void setModel(const OdometryMotionModel& model) {
    model_ = model;
    faults_.clampTo(model_.params());
  }

  /// Moves every particle by the noisy odometry motion from `from` to `to`,
  /// the tracker's share of them assuming a fault (and flagged so), on up
  /// to `threads` threads (the same result for any count); the noise of an
  /// update that brings a share `view_share` of a new view (view_share.h).
  void apply(const Pose2& from, const Pose2& to, ParticleSet* particles, Random* random,
             int threads = 1, double view_share = 1.0) {
    model_.apply(from, to, faults_.sampledFraction(), particles, random, faults_.flags(), threads,
                 view_share);
  }

  /// After the weighing of an update whose motion ran `step` m (`moved`:
  /// the particles were moved): the fault share learns which particles the
  /// scan favoured, where such a step shows it
  /// (OdometryFaultTracker::observable). Returns the share for the next update.
  double adaptFaults(bool moved, double step, const std::vector<double>& weights, int threads,
                     double view_share) {
    if (moved && OdometryFaultTracker::observable(step, model_.params())) {
      faults_.adapt(weights, model_.params(), threads, view_share);
    }
    return faults_.fraction();
  }
  /// Whether the scan pins the position along the track
  /// (OdometryFaultTracker::setAlongTrackObservable).
  void setAlongTrackObservable(bool observable) { faults_.setAlongTrackObservable(observable); }
  /// Whether the odometry is suspect: the faulty particles win (OdometryFaultTracker::suspect).
  bool suspect() const { return faults_.suspect(model_.params()); }
  /// Forgets the fault history (an initialisation).
  void restart() { faults_.restart(model_.params()); }
  /// Prefaults the fault flags for `n` particles.
  void reserve(std::size_t n) { faults_.reserve(n); }

  const OdometryMotionParams& params() const { return model_.params(); }

 private:
  OdometryMotionModel model_;
  OdometryFaultTracker faults_;
};

}  // namespace pf
