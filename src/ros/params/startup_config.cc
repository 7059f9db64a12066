#include "pf_localization/ros/params/startup_config.h"

#include <ros/console.h>

#include <memory>
#include <string>

namespace pf_ros {

std::optional<LocalizerConfig> readNodeConfig(const ros::NodeHandle& pnh) {
  try {
    std::unique_ptr<ParamSource> defaults;
    if (pnh.hasParam("defaults")) defaults = rosParamSource(ros::NodeHandle(pnh, "defaults"));
    ConfigNotes notes;
    LocalizerConfig config = readConfig(*rosParamSource(pnh), defaults.get(), &notes);
    for (const std::string& w : notes.warnings) ROS_WARN("pf_node: %s", w.c_str());
    for (const std::string& i : notes.infos) ROS_INFO("pf_node: %s", i.c_str());
    return config;
  } catch (const std::exception& e) {
    ROS_FATAL("pf_node: refusing to start: %s", e.what());
    return std::nullopt;
  }
}

std::optional<SavedPoseMap> readSavedPose(const ros::NodeHandle& pnh,
                                          const LocalizerConfig& config) {
  std::string value;
  if (!pnh.getParam(kSavedPoseMapParam, value)) return std::nullopt;
  const std::optional<SavedPoseMap> saved = parseSavedPoseMap(value);
  if (isSavedPose(saved, config.initial_pose)) return saved;
  if (config.initial_pose) {
    ROS_INFO("pf_node: the initial pose is not the one an earlier run saved (~%s): used as given",
             kSavedPoseMapParam);
  }
  return std::nullopt;
}

}  // namespace pf_ros
