// The parameters that may change while pf_node runs (dynamic_reconfigure,
// cfg/PfLocalization.cfg): which they are, and how a request for new values
// becomes a new, checked LocalizerConfig. Everything here is plain data and
// messages, so that it is unit-tested without a server (ReconfigureServer
// wires it to one).
//
// Not live: the frames, tf_broadcast, the initial pose (that is what
// initialpose is for), the seed, odom_model_type, laser_model_type,
// threads, save_pose_rate, first_map_only / use_map_topic.
#pragma once

#include <dynamic_reconfigure/Config.h>

#include <string>
#include <vector>

#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {

/// Names of every live parameter, as in config/pf.yaml and the .cfg (kld_z,
/// amcl's alias of kld_confidence, and amcl's restore_defaults action not included).
std::vector<std::string> liveParamNames();

/// The live parameters of `config` as a dynamic_reconfigure message, with
/// kld_z (amcl's name) computed from kld_confidence and restore_defaults false.
dynamic_reconfigure::Config liveParamsMessage(const LocalizerConfig& config);

/// Copies the live parameters of `from` into `to`; the rest of `to` stays.
void copyLiveParams(const LocalizerConfig& from, LocalizerConfig* to);

/// A request applied to the configuration in effect.
struct LiveChange {
  LocalizerConfig config;            // current with the request's values
  std::vector<std::string> changed;  // "name old -> new", in the .cfg's order
  std::string error;                 // non-empty: refused (readConfig's message)
};

/// Applies the values `request` holds (names it lacks keep their value) to
/// `current` and checks the result as readConfig does. kld_z, when it differs
/// from kld_confidence's quantile and kld_confidence itself is unchanged, sets
/// kld_confidence (amcl's name, as at start-up). laser_min_range and
/// laser_max_range below 0 mean 0, as at start-up.
LiveChange applyLiveParams(const LocalizerConfig& current,
                           const dynamic_reconfigure::Config& request);

}  // namespace pf_ros
