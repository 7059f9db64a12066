// pf_node: the live ROS front door of the particle filter, and only its
// wiring: it subscribes scan (or scan_topics, and cloud_topics), odom, map
// and initialpose, serves amcl's services and dynamic_reconfigure, reads the
// parameters, and hands each to the part that does the work: TfInput,
// ScanInputs and OdometryInput (the inputs), UpdateScheduler (where each
// update runs, and the filter's lock), LiveLocalizer (the filter and what goes
// with it: time jumping back, the saved pose, pf_pose, amcl_pose,
// particlecloud, the map's changes and clear_map_changes), MapToOdomRepublisher
// (map -> odom on tf), ReconfigureServer, and with ~floors_file Floors (the
// maps of a building's floors, change_floor).
//
// Threads (docs/ros-interface.md, "Threads, latency and overload"): tf, the
// scans, short updates and map -> odom's timer or /clock on roscpp's poll
// thread, longer updates on the scheduler's filter thread, the rest (and the
// pose's save) on the main spinner; the destructor stops them in order.
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/SetMap.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>

#include <csignal>
#include <memory>
#include <optional>
#include <vector>

#include "pf_localization/ros/input/odometry_input.h"
#include "pf_localization/ros/input/pose_transform.h"
#include "pf_localization/ros/input/scan_inputs.h"
#include "pf_localization/ros/input/tf_input.h"
#include "pf_localization/ros/localizer/floors.h"
#include "pf_localization/ros/localizer/live_localizer.h"
#include "pf_localization/ros/output/map_to_odom_republisher.h"
#include "pf_localization/ros/params/parameter_docs.h"
#include "pf_localization/ros/params/reconfigure_server.h"
#include "pf_localization/ros/params/startup_config.h"
#include "pf_localization/ros/scheduling/update_scheduler.h"

namespace pf_ros {
namespace {

constexpr double kLogPeriod = 5.0;  // s between two log lines about the same kind of bad input

// Set by SIGINT; the running node saves its pose, then shuts down (see main()).
volatile std::sig_atomic_t g_sigint = 0;
volatile std::sig_atomic_t g_node_running = 0;

class PfNode {
 public:
  // `saved`: config.initial_pose was saved by an earlier run (readSavedPose()).
  PfNode(const LocalizerConfig& config, std::optional<SavedPoseMap> saved,
         std::optional<pf::FloorsFile> floors, ros::NodeHandle nh, ros::NodeHandle pnh)
      : config_(config) {
    tf_ = std::make_unique<TfInput>(nh, &warn_);
    republisher_ = std::make_unique<MapToOdomRepublisher>(
        MapToOdomRepublisherOptions{config.tf_publish_rate, config.transform_tolerance,
                                    config.tf_broadcast},
        // Never waits for the filter: while an update runs, the next tick looks.
        [this](const ros::Time& now) {
          scheduler_->tryWithFilter([&] { live_->clockTick(now); });
        });
    live_ = std::make_unique<LiveLocalizer>(
        config, std::move(saved), &tf_->buffer(), republisher_.get(), &warn_, nh,
        [pnh](const PoseSaver::Record& record) { writeSavedPose(record, pnh); });
    scheduler_ = std::make_unique<UpdateScheduler>(
        [this](const PendingScan& scan, const LatestScanSlot& slot) {
          live_->processScan(scan, slot, *reconfigure_);
        },
        [this] { return live_->nextUpdateOnPollThread(); }, &warn_);
    odometry_ = std::make_unique<OdometryInput>(nh, config.odom_frame, config.base_frame,
                                                &tf_->buffer(), &warn_);
    map_sub_ = nh.subscribe<nav_msgs::OccupancyGrid>("map", 1, [this](const auto& msg) {
      live_->mapFromTopic(*msg, map_sub_.getTopic(), *scheduler_);
    });
    initial_pose_sub_ = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        "initialpose", 2, [this](const auto& msg) { live_->applyInitialPose(*msg, *scheduler_); });
    services_ = {nh.advertiseService("global_localization", &PfNode::onGlobalLocalization, this),
                 nh.advertiseService("request_nomotion_update", &PfNode::onNoMotionUpdate, this),
                 nh.advertiseService("set_map", &PfNode::onSetMap, this),
                 nh.advertiseService("clear_map_changes", &PfNode::onClearMapChanges, this)};
    reconfigure_ = std::make_unique<ReconfigureServer>(
        pnh, config,
        [this](const LocalizerConfig& c) {
          return scheduler_->withFilter([&] { return live_->reconfigure(c); });
        },
        "pf_node");
    republisher_->start(tf_->onPollThread(nh));
    scans_ = std::make_unique<ScanInputs>(
        scanTopics(config), cloudTopics(config), tf_->buffer(), config.odom_frame, tf_->queue(),
        [this](const sensor_msgs::LaserScanConstPtr& scan, std::size_t sensor) {
          scheduler_->onScan({scan, ros::WallTime::now(), ros::Time::now(), sensor, nullptr});
        },
        [this](const sensor_msgs::PointCloud2ConstPtr& cloud, std::size_t sensor) {
          scheduler_->onScan({nullptr, ros::WallTime::now(), ros::Time::now(), sensor, cloud});
        },
        // On the main spinner: it takes the filter's lock, which the thread
        // that dropped the scan may hold (its map -> odom reached tf).
        [this](const std_msgs::Header& header,
               tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          postCallback(ros::getGlobalCallbackQueue(), reinterpret_cast<uint64_t>(this), [=] {
            scheduler_->withFilter([&] { live_->scanDropped(header, reason); });
          });
        });
    floors_ = Floors::create(
        std::move(floors), live_.get(), scheduler_.get(),
        [this](const auto& pose) {
          return initialPoseInFrame(tf_->buffer(), pose, config_.global_frame, &warn_);
        },
        nh);
    scans_->subscribe(nh);  // last: their callbacks may run at once, on the poll thread
  }

  // First what brings scans, then the filter thread, then what its updates use.
  ~PfNode() {
    floors_.reset();
    scans_.reset();
    ros::getGlobalCallbackQueue()->removeByID(reinterpret_cast<uint64_t>(this));
    scheduler_->stop();
    republisher_.reset();  // its tick uses the scheduler and live_
    reconfigure_.reset();
    odometry_.reset();
    scheduler_.reset();
    live_.reset();
    tf_.reset();
  }

  // roscpp's own loop (ros::spin() waits the same 0.1 s of wall time: a paused
  // bag clock must not keep Ctrl-C waiting), plus a look at the periodic save
  // and at Ctrl-C (and roslaunch's shutdown), which saves the pose, then stops.
  void spin() {
    while (ros::ok()) {
      ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
      live_->saver().saveWhenDue(ros::Time::now());
      if (!g_sigint) continue;
      live_->saveAtShutdown(*scheduler_);
      ros::shutdown();
    }
  }

 private:
  bool onSetMap(nav_msgs::SetMap::Request& req, nav_msgs::SetMap::Response& res) {
    res.success = live_->setMap(req, *scheduler_);
    return true;
  }

  bool onGlobalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    return live_->globalLocalization(*scheduler_);
  }

  bool onClearMapChanges(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    return scheduler_->withFilter([&] { return live_->clearMapChanges(); });
  }

  bool onNoMotionUpdate(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    scheduler_->withFilter([&] { live_->requestNoMotionUpdate(); });
    return true;
  }

  // Made in the constructor's body and stopped in the destructor's, in the
  // order their threads need: the members' order does not matter.
  const LocalizerConfig config_;  // as read: the live values are live_'s
  LimitedWarn warn_{"pf_node", kLogPeriod};
  std::unique_ptr<TfInput> tf_;
  std::unique_ptr<MapToOdomRepublisher> republisher_;
  std::unique_ptr<LiveLocalizer> live_;
  std::unique_ptr<UpdateScheduler> scheduler_;
  std::unique_ptr<OdometryInput> odometry_;
  std::unique_ptr<ReconfigureServer> reconfigure_;
  std::unique_ptr<ScanInputs> scans_;
  std::unique_ptr<Floors> floors_;  // with ~floors_file only
  ros::Subscriber map_sub_, initial_pose_sub_;
  std::vector<ros::ServiceServer> services_;
};

}  // namespace
}  // namespace pf_ros

int main(int argc, char** argv) {
  if (pf_ros::printHelpIfAsked(argc, argv, "pf_node")) return 0;
  // roscpp's own SIGINT handler would shut down before the pose is saved.
  ros::init(argc, argv, "pf_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, [](int) {
    pf_ros::g_sigint = 1;
    // Before the node runs (waiting for a master, say) there is nothing to
    // save: stop at once, as roscpp's handler does.
    if (!pf_ros::g_node_running) ros::requestShutdown();
  });
  ros::NodeHandle nh, pnh("~");
  const std::optional<pf_ros::LocalizerConfig> config = pf_ros::readNodeConfig(pnh);
  if (!config) return 1;
  std::optional<pf::FloorsFile> floors;
  if (!config->floors_file.empty() && !(floors = pf_ros::Floors::read(config->floors_file)))
    return 1;
  pf_ros::PfNode node(*config, pf_ros::readSavedPose(pnh, *config), std::move(floors), nh, pnh);
  pf_ros::g_node_running = 1;
  node.spin();
  return 0;
}
