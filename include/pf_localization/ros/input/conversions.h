// Conversions between ROS messages and the core's ROS-free types.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovariance.h>
#include <geometry_msgs/Transform.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>

#include <Eigen/Core>

#include "pf_localization/PoseHypotheses.h"
#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/util/pose2.h"

namespace pf_ros {

/// Yaw of a quaternion (roll and pitch are ignored: we live in the plane).
double yawOf(const geometry_msgs::Quaternion& q);
geometry_msgs::Quaternion quaternionFromYaw(double yaw);

pf::Pose2 toPose2(const geometry_msgs::Pose& p);
pf::Pose2 toPose2(const geometry_msgs::Transform& t);
geometry_msgs::Pose toPoseMsg(const pf::Pose2& p);
geometry_msgs::Transform toTransformMsg(const pf::Pose2& p);

/// The scan with the laser's pose on the robot attached.
pf::LaserScan toCore(const sensor_msgs::LaserScan& msg, const pf::Pose2& sensor_pose);
/// Throws std::invalid_argument for a malformed grid (size mismatch, zero size, bad resolution).
/// The float32 resolution is read as the shortest decimal that gives the same
/// float (0.05f -> 0.05), so toCore(toMsg(g)) == g for map-file resolutions.
pf::OccupancyGrid toCore(const nav_msgs::OccupancyGrid& msg);
/// Info and data only: the caller fills the header and map_load_time.
nav_msgs::OccupancyGrid toMsg(const pf::OccupancyGrid& grid);
/// The grid's size, resolution and origin, as toMsg gives them
/// (map_load_time unset).
nav_msgs::MapMetaData toMapInfo(const pf::OccupancyGrid& grid);

/// The 6x6 ROS covariance (x, y, z, roll, pitch, yaw) from the 3x3 (x, y, yaw)
/// one; z, roll and pitch get zero variance.
boost::array<double, 36> toRosCovariance(const Eigen::Matrix3d& cov);
/// The (x, y, yaw) block of a ROS 6x6 covariance.
Eigen::Matrix3d fromRosCovariance(const boost::array<double, 36>& cov);

/// Every particle as a pose (weights are not part of a PoseArray); the header is left as it is.
void toPoseArray(const pf::ParticleSet& particles, geometry_msgs::PoseArray* out);

/// At most `max_poses` poses that show the cloud's shape (0: every particle):
/// with more particles than that, a systematic resample by weight (evenly
/// spaced points on the cumulative weight, the first at half a step), so
/// that each pose stands for the same share of the weight, as the
/// particles themselves do after a resampling. Deterministic; O(N). For
/// particlecloud: 500 000 poses are 28 MB a message, and rviz shows the same
/// shape with a few thousand.
void toPoseArray(const pf::ParticleSet& particles, std::size_t max_poses,
                 geometry_msgs::PoseArray* out);

/// The hypotheses as pf_hypotheses publishes them: the count, and each
/// listed one's pose with its covariance, weight and particle count, in the
/// same order (heaviest first); the header is left as it is.
void toHypothesesMsg(const pf::Hypotheses& hypotheses, pf_localization::PoseHypotheses* out);

}  // namespace pf_ros
