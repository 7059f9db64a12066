// pf_node's dynamic_reconfigure server (cfg/PfLocalization.cfg): what
// rqt_reconfigure and `rosrun dynamic_reconfigure dynparam` talk to, under the
// node's private namespace (/pf_node, or /amcl in launch/amcl_compatible.launch).
//
// It starts from the configuration the node read at start-up (not from the
// .cfg's defaults, nor from the parameter server alone: that is readConfig's
// job, amcl's names and ~defaults included). A request is checked as at
// start-up (live_params.h); an invalid one is refused whole, logged as an
// error with the start-up message, and the values in effect are sent back so
// that the client shows them. An accepted one goes to `apply`, the INFO log
// lists what changed, and the generation counts up. restore_defaults (amcl's)
// asks for the start-up values.
#pragma once

#include <dynamic_reconfigure/Config.h>
#include <ros/node_handle.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {

class ReconfigureServer {
 public:
  /// Puts the new configuration in effect; returns an error message (empty
  /// on success), after which the previous configuration must still be in effect.
  using Apply = std::function<std::string(const LocalizerConfig&)>;

  /// Serves on `private_nh` (the node's ~). `log_prefix` starts every log line.
  ReconfigureServer(const ros::NodeHandle& private_nh, const LocalizerConfig& initial, Apply apply,
                    std::string log_prefix);
  ~ReconfigureServer();
  ReconfigureServer(const ReconfigureServer&) = delete;
  ReconfigureServer& operator=(const ReconfigureServer&) = delete;

  /// The configuration in effect (its live parameters are the server's).
  const LocalizerConfig& config() const { return current_; }
  /// How many changes were accepted since start-up (0: the start-up values).
  int generation() const { return generation_.load(); }

 private:
  struct Server;
  // Called by the server with the requested values, which it publishes as
  // they are left: the accepted request, or the values in effect.
  void onRequest(dynamic_reconfigure::Config* request);

  const LocalizerConfig initial_;  // restore_defaults goes back to it
  LocalizerConfig current_;
  Apply apply_;
  std::string log_prefix_;
  // Atomic: pf_node's filter thread reads it for the diagnostics.
  std::atomic<int> generation_{0};
  std::unique_ptr<Server> server_;
};

}  // namespace pf_ros
