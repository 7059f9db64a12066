#include "pf_localization/ros/input/conversions.h"

#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace pf_ros {
namespace {

// Where x, y and yaw sit in ROS's (x, y, z, roll, pitch, yaw) covariance.
constexpr std::array<int, 3> kRosIndex = {0, 1, 5};

// MapMetaData stores the resolution as float32, so a map saved at 0.05 m
// arrives as 0.0500000007. Reading back the shortest decimal that gives the
// same float recovers the YAML's 0.05, so a grid received on /map is identical
// to the one loadMap() builds from the file (pf_node and pf_bag_runner then
// agree to the last bit).
double cleanResolution(float r) {
  std::array<char, 32> buf;
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size() - 1, r);
  *res.ptr = '\0';
  return std::strtod(buf.data(), nullptr);
}

}  // namespace

double yawOf(const geometry_msgs::Quaternion& q) {
  // The ZYX-Euler yaw, as tf2::getYaw. w^2 + x^2 - y^2 - z^2 instead of the
  // usual 1 - 2(y^2 + z^2) keeps it right for quaternions that are not unit
  // length (hand-typed /initialpose messages often are not).
  const double siny = 2.0 * (q.w * q.z + q.x * q.y);
  const double cosy = q.w * q.w + q.x * q.x - q.y * q.y - q.z * q.z;
  return pf::normalizeAngle(std::atan2(siny, cosy));
}

geometry_msgs::Quaternion quaternionFromYaw(double yaw) {
  geometry_msgs::Quaternion q;
  q.x = 0.0;
  q.y = 0.0;
  q.z = std::sin(0.5 * yaw);
  q.w = std::cos(0.5 * yaw);
  return q;
}

pf::Pose2 toPose2(const geometry_msgs::Pose& p) {
  return {p.position.x, p.position.y, yawOf(p.orientation)};
}

pf::Pose2 toPose2(const geometry_msgs::Transform& t) {
  return {t.translation.x, t.translation.y, yawOf(t.rotation)};
}

geometry_msgs::Pose toPoseMsg(const pf::Pose2& p) {
  geometry_msgs::Pose msg;
  msg.position.x = p.x;
  msg.position.y = p.y;
  msg.position.z = 0.0;
  msg.orientation = quaternionFromYaw(p.yaw);
  return msg;
}

geometry_msgs::Transform toTransformMsg(const pf::Pose2& p) {
  geometry_msgs::Transform msg;
  msg.translation.x = p.x;
  msg.translation.y = p.y;
  msg.translation.z = 0.0;
  msg.rotation = quaternionFromYaw(p.yaw);
  return msg;
}

pf::LaserScan toCore(const sensor_msgs::LaserScan& msg, const pf::Pose2& sensor_pose) {
  // angle_max is implied by angle_min, angle_increment and the beam count;
  // drivers disagree on whether it names the last beam or one past it.
  pf::LaserScan scan;
  scan.ranges = msg.ranges;
  scan.angle_min = msg.angle_min;
  scan.angle_increment = msg.angle_increment;
  scan.range_min = msg.range_min;
  scan.range_max = msg.range_max;
  scan.sensor_pose = sensor_pose;
  return scan;
}

pf::OccupancyGrid toCore(const nav_msgs::OccupancyGrid& msg) {
  const uint64_t w = msg.info.width, h = msg.info.height;
  // OccupancyGrid indexes cells with int.
  if (w > INT_MAX || h > INT_MAX || w * h > INT_MAX) {
    throw std::invalid_argument("OccupancyGrid message: " + std::to_string(w) + " x " +
                                std::to_string(h) + " cells is too large");
  }
  if (msg.data.size() != w * h) {
    throw std::invalid_argument("OccupancyGrid message: " + std::to_string(msg.data.size()) +
                                " cell values for a " + std::to_string(w) + " x " +
                                std::to_string(h) + " grid");
  }
  // The constructor rejects a zero size and a bad resolution or origin.
  return pf::OccupancyGrid(static_cast<int>(w), static_cast<int>(h),
                           cleanResolution(msg.info.resolution), toPose2(msg.info.origin),
                           std::vector<int8_t>(msg.data.begin(), msg.data.end()));
}

nav_msgs::MapMetaData toMapInfo(const pf::OccupancyGrid& grid) {
  nav_msgs::MapMetaData info;
  info.width = static_cast<uint32_t>(grid.width());
  info.height = static_cast<uint32_t>(grid.height());
  info.resolution = static_cast<float>(grid.resolution());
  info.origin = toPoseMsg(grid.origin());
  return info;
}

nav_msgs::OccupancyGrid toMsg(const pf::OccupancyGrid& grid) {
  nav_msgs::OccupancyGrid msg;
  msg.info = toMapInfo(grid);
  msg.data.assign(grid.data().begin(), grid.data().end());
  return msg;
}

boost::array<double, 36> toRosCovariance(const Eigen::Matrix3d& cov) {
  boost::array<double, 36> out;
  out.fill(0.0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[6 * kRosIndex[i] + kRosIndex[j]] = cov(i, j);
  }
  return out;
}

Eigen::Matrix3d fromRosCovariance(const boost::array<double, 36>& cov) {
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out(i, j) = cov[6 * kRosIndex[i] + kRosIndex[j]];
  }
  return out;
}

void toPoseArray(const pf::ParticleSet& particles, geometry_msgs::PoseArray* out) {
  out->poses.resize(particles.size());
  for (std::size_t i = 0; i < particles.size(); ++i) out->poses[i] = toPoseMsg(particles.pose(i));
}

void toPoseArray(const pf::ParticleSet& particles, std::size_t max_poses,
                 geometry_msgs::PoseArray* out) {
  const std::size_t n = particles.size();
  if (max_poses == 0 || n <= max_poses) {
    toPoseArray(particles, out);
    return;
  }
  double total = 0.0;
  for (double w : particles.weight) total += w;
  out->poses.clear();
  out->poses.reserve(max_poses);
  if (!(total > 0.0) || !std::isfinite(total)) {
    // No usable weights: every (n / max_poses)-th particle.
    for (std::size_t k = 0; k < max_poses; ++k) {
      out->poses.push_back(toPoseMsg(particles.pose(k * n / max_poses)));
    }
    return;
  }
  const double step = total / static_cast<double>(max_poses);
  double target = 0.5 * step;
  double cumulative = particles.weight[0];
  std::size_t i = 0;
  for (std::size_t k = 0; k < max_poses; ++k, target += step) {
    while (cumulative < target && i + 1 < n) cumulative += particles.weight[++i];
    out->poses.push_back(toPoseMsg(particles.pose(i)));
  }
}

void toHypothesesMsg(const pf::Hypotheses& hypotheses, pf_localization::PoseHypotheses* out) {
  out->count = static_cast<uint32_t>(hypotheses.count);
  out->poses.resize(hypotheses.listed.size());
  out->weights.resize(hypotheses.listed.size());
  out->particles.resize(hypotheses.listed.size());
  for (std::size_t k = 0; k < hypotheses.listed.size(); ++k) {
    const pf::Hypothesis& h = hypotheses.listed[k];
    out->poses[k].pose = toPoseMsg(h.pose);
    out->poses[k].covariance = toRosCovariance(h.covariance);
    out->weights[k] = h.weight;
    out->particles[k] = static_cast<uint32_t>(h.particles);
  }
}

}  // namespace pf_ros
