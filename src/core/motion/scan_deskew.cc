#include "pf_localization/core/motion/scan_deskew.h"

#include <cmath>

namespace pf {
namespace {

// Below this turn the arc formulas divide by ~0; a straight line is exact to
// within 1e-19 m per metre there.
constexpr double kStraight = 1e-9;

}  // namespace

Pose2 velocityBetween(const Pose2& earlier, const Pose2& later, double dt) {
  const Pose2 d = between(earlier, later);
  const double theta = d.yaw;
  if (std::fabs(theta) < kStraight) return {d.x / dt, d.y / dt, theta / dt};
  // Invert the arc of motionOver: [x; y] = V [vx; vy] * dt with
  // V = [a -b; b a], a = sin(theta) / theta, b = (1 - cos(theta)) / theta.
  const double a = std::sin(theta) / theta;
  const double b = (1.0 - std::cos(theta)) / theta;
  const double det = a * a + b * b;
  const double vx = (a * d.x + b * d.y) / det;
  const double vy = (-b * d.x + a * d.y) / det;
  return {vx / dt, vy / dt, theta / dt};
}

Pose2 motionOver(const Pose2& velocity, double dt) {
  const double theta = velocity.yaw * dt;
  const double vx = velocity.x * dt, vy = velocity.y * dt;
  if (std::fabs(theta) < kStraight) return {vx, vy, theta};
  const double a = std::sin(theta) / theta;
  const double b = (1.0 - std::cos(theta)) / theta;
  return {a * vx - b * vy, b * vx + a * vy, normalizeAngle(theta)};
}

Pose2 sensorPoseAtBeam(const Pose2& sensor_pose, const SweepMotion& sweep, std::size_t index) {
  if (sweep.isStill()) return sensor_pose;
  const double t = sweep.first_beam_time + static_cast<double>(index) * sweep.time_increment;
  return compose(motionOver(sweep.base_velocity, t), sensor_pose);
}

}  // namespace pf
