// A differential-drive robot whose wheel odometry drifts from its true motion.
//
// The true pose follows the commanded (v, w) exactly: the simulator steers
// the robot itself, not its odometry, so a scripted path stays where the
// script puts it and collision checks on the script are exact.
//
// Odometry is reconstructed the way a real robot does it, from wheel
// rotations. For a true step (ds, dtheta) each wheel's ground travel is
//   d_l = ds - dtheta * B / 2,   d_r = ds + dtheta * B / 2
// with B the true track width. A wheel of true radius r (1 + e) turns
// d / (r (1 + e)) radians for it, plus slip: zero-mean Gaussian noise whose
// variance grows linearly with the distance travelled (a random walk, so the
// result does not depend on the step size). The odometry believes the nominal
// radius r and track width b and integrates
//   ds_o = (phi_l + phi_r) r / 2,   dtheta_o = (phi_r - phi_l) r / b
// as an exact circular arc. Wheel radius errors scale distances (and, when
// the two wheels differ, bend straight lines); a track width error scales
// rotations.
#pragma once

#include "pf_localization/core/util/pose2.h"
#include "pf_localization/sim/sim_random.h"

namespace pf::sim {

struct DiffDriveParams {
  double track_width = 0.248;       // m, nominal (what the odometry assumes); Neato XV-11
  double left_radius_error = 0.0;   // true left wheel radius = nominal * (1 + this)
  double right_radius_error = 0.0;  // true right wheel radius = nominal * (1 + this)
  double track_width_error = 0.0;   // true track width = nominal * (1 + this)
  double slip_sigma = 0.0;          // m / sqrt(m): per-wheel slip std after 1 m of travel
  // Encoders that count ticks without their direction, as the CARMEN logs
  // show: the odometry's forward travel is always positive, so a reversing
  // robot is logged as driving forwards (turns keep their sign).
  bool unsigned_translation = false;
};

/// The pose reached from `p` by driving `ds` along a circular arc that turns
/// by `dtheta` (a straight line when dtheta is 0).
Pose2 integrateArc(const Pose2& p, double ds, double dtheta);

class DiffDriveRobot {
 public:
  /// The true pose starts at `start`; the odometry starts at the origin.
  DiffDriveRobot(const DiffDriveParams& params, const Pose2& start);

  /// Drives at (v, w) for dt seconds. `random` supplies the slip; it may be
  /// null when slip_sigma is 0.
  void step(double v, double w, double dt, SimRandom* random);

  /// Moves the true pose without the wheels turning (a kidnapping).
  void teleport(const Pose2& pose) { true_pose_ = pose; }

  const Pose2& truePose() const { return true_pose_; }
  const Pose2& odomPose() const { return odom_pose_; }
  /// Velocities the odometry measured over the last step (base frame).
  double odomLinearVelocity() const { return odom_v_; }
  double odomAngularVelocity() const { return odom_w_; }

 private:
  DiffDriveParams params_;
  Pose2 true_pose_;
  Pose2 odom_pose_;
  double odom_v_ = 0.0;
  double odom_w_ = 0.0;
};

}  // namespace pf::sim
