// Every tunable of the localizer, read from one place, with the same names in
// config/pf.yaml, on the ROS parameter server and in pf_bag_runner's
// --params file. Each parameter's meaning, unit and default is documented in
// config/pf.yaml.
#pragma once

#include <ros/node_handle.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "pf_localization/core/particle_filter.h"

namespace pf_ros {

struct LocalizerConfig {
  std::string global_frame = "map";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  double transform_tolerance = 0.1;  // s the published map->odom is post-dated by
  double tf_publish_rate = 20.0;     // Hz map->odom is republished between updates
  bool tf_broadcast = true;
  std::optional<pf::Pose2> initial_pose;  // none: global localization
  Eigen::Matrix3d initial_cov = Eigen::Vector3d(0.25, 0.25, 0.0685).asDiagonal();
  pf::ParticleFilterParams filter;
};

/// Where parameters come from: the ROS parameter server, or a YAML file.
/// Each getter leaves `value` alone and returns false when the key is absent.
class ParamSource {
 public:
  virtual ~ParamSource() = default;
  virtual bool get(const std::string& key, double* value) const = 0;
  virtual bool get(const std::string& key, int* value) const = 0;
  virtual bool get(const std::string& key, bool* value) const = 0;
  virtual bool get(const std::string& key, std::string* value) const = 0;
};

/// A ParamSource over a flat YAML mapping (config/pf.yaml's format).
/// Throws std::runtime_error naming the file when it cannot be read.
std::unique_ptr<ParamSource> yamlParamSource(const std::string& path);

/// A ParamSource over a node's (usually private) namespace.
std::unique_ptr<ParamSource> rosParamSource(const ros::NodeHandle& nh);

/// Reads every parameter (absent ones keep their defaults) and validates the
/// result. Throws std::invalid_argument naming the parameter and its valid range.
LocalizerConfig readConfig(const ParamSource& source);

}  // namespace pf_ros
