// De-skewing a scan taken while the robot moves.
//
// A spinning lidar takes its beams one after another: a Neato's turret needs
// 0.2 s per turn, so at 1 rad/s its last beam is taken 11 degrees after the
// first, and a scan drawn as if from one pose is bent. The filter matches that
// bent scan to a straight map: the fit is worse when turning, and the estimate
// lags or leads by up to half a sweep. De-skewing places each beam from where
// the sensor was when it was taken.
//
// The motion within a sweep is short (<= 0.2 s), so it is modelled as a
// constant body-frame velocity (a twist), estimated from two odometry poses
// and integrated exactly on SE(2) (a circular arc). This is the usual
// correction of lidar odometry and mapping systems (e.g. LOAM, Zhang and
// Singh, RSS 2014, which interpolates the sweep's motion linearly), reduced to
// the plane and to what odometry alone can tell.
#pragma once

#include <cstddef>

#include "pf_localization/core/util/pose2.h"

namespace pf {

/// When the beams of a scan were taken, and how the robot moved meanwhile.
/// All zeros (the default) means "one instant": no correction.
struct SweepMotion {
  // s from the scan's reference time (that of the odometry pose the scan is
  // paired with) to its first beam: 0 when the stamp is the first beam's
  // (ROS's convention), -(n - 1) * time_increment when it is the last beam's.
  double first_beam_time = 0.0;
  double time_increment = 0.0;  // s between consecutive beams
  // The base's velocity at the reference time, in its own frame:
  // x, y in m/s, yaw in rad/s.
  Pose2 base_velocity;

  bool isStill() const {
    return time_increment == 0.0 ||
           (base_velocity.x == 0.0 && base_velocity.y == 0.0 && base_velocity.yaw == 0.0);
  }
};

/// The constant body-frame velocity that moves `earlier` onto `later` in `dt`
/// seconds (the SE(2) logarithm of the relative pose, over dt). dt must be > 0.
Pose2 velocityBetween(const Pose2& earlier, const Pose2& later, double dt);

/// The pose reached after `dt` seconds at the body-frame `velocity`, starting
/// from the identity (the SE(2) exponential): a circular arc, or a straight
/// line when the yaw rate is zero. dt may be negative (where it came from).
Pose2 motionOver(const Pose2& velocity, double dt);

/// The sensor's pose, in the base frame at the reference time, when beam
/// `index` was taken: `sensor_pose` (the mounting) carried along by the
/// base's motion. Equal to `sensor_pose` when the sweep is still.
Pose2 sensorPoseAtBeam(const Pose2& sensor_pose, const SweepMotion& sweep, std::size_t index);

}  // namespace pf
