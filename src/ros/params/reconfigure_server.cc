#include "pf_localization/ros/params/reconfigure_server.h"

#include <dynamic_reconfigure/server.h>
#include <pf_localization/PfLocalizationConfig.h>
#include <ros/console.h>

#include <boost/thread/recursive_mutex.hpp>
#include <utility>

#include "pf_localization/ros/params/live_params.h"

namespace pf_ros {

// The generated type stays out of the header: only this file needs the
// build's generated include directory.
struct ReconfigureServer::Server {
  explicit Server(const ros::NodeHandle& nh) : server(mutex, nh) {}
  boost::recursive_mutex mutex;  // the server's; updateConfig from outside would take it
  dynamic_reconfigure::Server<pf_localization::PfLocalizationConfig> server;
};

namespace {

// `config` with the live parameters (and kld_z) of `msg`; its groups stay.
void setValues(const dynamic_reconfigure::Config& msg,
               pf_localization::PfLocalizationConfig* config) {
  dynamic_reconfigure::Config copy = msg;
  config->__fromMessage__(copy);
}

}  // namespace

ReconfigureServer::ReconfigureServer(const ros::NodeHandle& private_nh,
                                     const LocalizerConfig& initial, Apply apply,
                                     std::string log_prefix)
    : initial_(initial),
      current_(initial),
      apply_(std::move(apply)),
      log_prefix_(std::move(log_prefix)) {
  server_ = std::make_unique<Server>(private_nh);
  // The server starts from the .cfg's defaults and whatever the parameter
  // server holds under our names; the values in effect replace both before
  // the first request (setCallback calls back with them, which accepts them
  // as no change).
  pf_localization::PfLocalizationConfig start =
      pf_localization::PfLocalizationConfig::__getDefault__();
  setValues(liveParamsMessage(current_), &start);
  server_->server.updateConfig(start);
  server_->server.setCallback([this](pf_localization::PfLocalizationConfig& config, uint32_t) {
    dynamic_reconfigure::Config msg;
    config.__toMessage__(msg);
    onRequest(&msg);
    setValues(msg, &config);
  });
}

ReconfigureServer::~ReconfigureServer() = default;

void ReconfigureServer::onRequest(dynamic_reconfigure::Config* request) {
  // amcl's restore_defaults: the values the node started with, as amcl does.
  for (const auto& b : request->bools) {
    if (b.name == "restore_defaults" && b.value) *request = liveParamsMessage(initial_);
  }
  LiveChange change = applyLiveParams(current_, *request);
  if (change.error.empty() && change.changed.empty()) {
    *request = liveParamsMessage(current_);  // kld_z in step with kld_confidence
    return;
  }
  if (change.error.empty()) change.error = apply_(change.config);
  if (!change.error.empty()) {
    ROS_ERROR("%s: refusing the new parameters: %s; the previous values stay in effect",
              log_prefix_.c_str(), change.error.c_str());
    *request = liveParamsMessage(current_);
    return;
  }
  current_ = change.config;
  ++generation_;
  std::string list;
  for (const std::string& c : change.changed) list += (list.empty() ? "" : ", ") + c;
  ROS_INFO("%s: reconfigured (generation %d): %s", log_prefix_.c_str(), generation_.load(),
           list.c_str());
  *request = liveParamsMessage(current_);
}

}  // namespace pf_ros
