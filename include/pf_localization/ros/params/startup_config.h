// pf_node's configuration at start-up, from the parameter server: its
// private parameters over ~defaults (launch/amcl_compatible.launch loads
// config/pf.yaml there, so that amcl's names in ~ override it), and whether
// the initial pose among them is one an earlier run saved (saved_pose.h).
#pragma once

#include <ros/node_handle.h>

#include <optional>

#include "pf_localization/ros/params/localizer_config.h"
#include "pf_localization/ros/params/saved_pose.h"

namespace pf_ros {

/// readConfig() on `pnh` over `pnh`/defaults, its notes logged. Nothing when
/// the configuration is invalid (logged at FATAL, naming the parameter).
std::optional<LocalizerConfig> readNodeConfig(const ros::NodeHandle& pnh);

/// ~saved_pose_map, when `config`'s initial pose is the one it records
/// (isSavedPose()); nothing otherwise, and the pose is used as given.
std::optional<SavedPoseMap> readSavedPose(const ros::NodeHandle& pnh,
                                          const LocalizerConfig& config);

}  // namespace pf_ros
