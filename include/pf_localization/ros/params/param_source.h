// Where the parameters are read from (readConfig, localizer_config.h): the
// ROS parameter server (a node's namespace, fetched in one call) or a flat
// YAML file (config/pf.yaml's format, pf_bag_runner's --params).
#pragma once

#include <ros/node_handle.h>

#include <memory>
#include <string>
#include <vector>

namespace pf_ros {

/// Where parameters come from: the ROS parameter server, or a YAML file.
/// Each getter leaves `value` alone and returns false when the key is absent.
class ParamSource {
 public:
  virtual ~ParamSource() = default;
  virtual bool get(const std::string& key, double* value) const = 0;
  virtual bool get(const std::string& key, int* value) const = 0;
  virtual bool get(const std::string& key, bool* value) const = 0;
  virtual bool get(const std::string& key, std::string* value) const = 0;
  /// The names present at the top level, for the unknown-parameter warning
  /// (a source that cannot list them returns none, and nothing is warned about).
  virtual std::vector<std::string> keys() const { return {}; }
};

/// A ParamSource over a flat YAML mapping (config/pf.yaml's format).
/// Throws std::runtime_error naming the file when it cannot be read.
std::unique_ptr<ParamSource> yamlParamSource(const std::string& path);

/// A ParamSource over a node's (usually private) namespace.
std::unique_ptr<ParamSource> rosParamSource(const ros::NodeHandle& nh);

}  // namespace pf_ros
