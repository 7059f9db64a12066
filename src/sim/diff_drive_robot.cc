#include "pf_localization/sim/diff_drive_robot.h"

#include <cmath>

namespace pf::sim {

Pose2 integrateArc(const Pose2& p, double ds, double dtheta) {
  // Driving an arc is the same as driving its chord, whose heading is halfway
  // through the turn; the chord is shorter than the arc by sin(h) / h.
  const double h = 0.5 * dtheta;
  const double chord = std::abs(h) < 1e-9 ? ds : ds * std::sin(h) / h;
  const double heading = p.yaw + h;
  return {p.x + chord * std::cos(heading), p.y + chord * std::sin(heading),
          normalizeAngle(p.yaw + dtheta)};
}

DiffDriveRobot::DiffDriveRobot(const DiffDriveParams& params, const Pose2& start)
    : params_(params), true_pose_(start) {}

void DiffDriveRobot::step(double v, double w, double dt, SimRandom* random) {
  const double ds = v * dt;
  const double dtheta = w * dt;
  true_pose_ = integrateArc(true_pose_, ds, dtheta);

  // Wheel rotations in units of the nominal radius (r cancels out of the
  // odometry, so it never needs a value).
  const double true_track = params_.track_width * (1.0 + params_.track_width_error);
  double left = ds - 0.5 * dtheta * true_track;
  double right = ds + 0.5 * dtheta * true_track;
  if (params_.slip_sigma > 0.0 && random != nullptr) {
    left += random->gaussian(params_.slip_sigma * std::sqrt(std::abs(left)));
    right += random->gaussian(params_.slip_sigma * std::sqrt(std::abs(right)));
  }
  left /= 1.0 + params_.left_radius_error;
  right /= 1.0 + params_.right_radius_error;

  const double ds_odom =
      params_.unsigned_translation ? std::abs(0.5 * (left + right)) : 0.5 * (left + right);
  const double dtheta_odom = (right - left) / params_.track_width;
  odom_pose_ = integrateArc(odom_pose_, ds_odom, dtheta_odom);
  odom_v_ = dt > 0.0 ? ds_odom / dt : 0.0;
  odom_w_ = dt > 0.0 ? dtheta_odom / dt : 0.0;
}

}  // namespace pf::sim
