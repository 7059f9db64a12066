// pf_node: the live ROS front door of the particle filter.
//
// Subscribes scan (or each of scan_topics, and of cloud_topics: PointCloud2),
// odom, map (latched) and initialpose; publishes map -> odom
// on tf, the particles on particlecloud and the estimate on pf_pose and
// amcl_pose. The localization happens in pf_ros::ScanLocalizer and the core,
// what goes with the filter (time jumping back, the saved pose, the output)
// in pf_ros::LiveLocalizer; this file wires them to roscpp. It speaks amcl's
// interface too (topics, services, parameter names, the saved pose,
// dynamic_reconfigure), so that it can replace amcl in a bringup.
//
// Threads (docs/ros-interface.md, "Threads, latency and overload"): tf and the
// scans are taken on roscpp's own poll thread as they arrive
// (InlineCallbackQueue: no hand-off to a spinner); a scan whose tf is there
// goes to the UpdateScheduler, which updates it at once on that thread when
// the update will be short, otherwise hands it to a filter thread of its
// own, so that under overload the newest scan wins and tf keeps being
// consumed; the main spinner serves the map, initialpose, odometry, the
// services, the periodic save and the scans tf dropped; map -> odom is
// republished by a MapToOdomRepublisher (on the poll thread: a timer in
// roscpp's poll set on the wall clock, /clock under simulated time) that
// never waits for the filter. No roscpp timer: under simulated time one polls
// the clock every millisecond. The scheduler's lock protects the filter and
// everything that goes with it (live_).
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/SetMap.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include <csignal>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pf_localization/ros/diagnostics/limited_warn.h"
#include "pf_localization/ros/input/odometry_source.h"
#include "pf_localization/ros/input/pose_transform.h"
#include "pf_localization/ros/input/scan_inputs.h"
#include "pf_localization/ros/localizer/live_localizer.h"
#include "pf_localization/ros/output/map_to_odom_republisher.h"
#include "pf_localization/ros/params/parameter_docs.h"
#include "pf_localization/ros/params/reconfigure_server.h"
#include "pf_localization/ros/params/startup_config.h"
#include "pf_localization/ros/scheduling/inline_callback_queue.h"
#include "pf_localization/ros/scheduling/update_scheduler.h"

namespace pf_ros {
namespace {

// s between two log lines about the same kind of bad input.
constexpr double kLogPeriod = 5.0;

// Set by SIGINT; the running node saves its pose, then shuts down (see main()).
volatile std::sig_atomic_t g_sigint = 0;
volatile std::sig_atomic_t g_node_running = 0;

class PfNode {
 public:
  // `saved`: config.initial_pose was saved by an earlier run (readSavedPose()).
  PfNode(const LocalizerConfig& config, std::optional<SavedPoseMap> saved, ros::NodeHandle nh,
         ros::NodeHandle pnh)
      : config_(config),
        nh_(nh),
        pnh_(pnh),
        buffer_(ros::Duration(30.0)),
        inline_queue_(ros::getGlobalCallbackQueue()),
        // tf as it arrives, with no thread or spinner of the listener's own: a
        // transform that completes a waiting scan hands it to the filter thread
        // directly (docs/performance.md, "Wake-ups: tf and scans on the poll thread").
        listener_(buffer_, withQueue(nh_, &inline_queue_), false),
        republisher_(std::make_unique<MapToOdomRepublisher>(
            MapToOdomRepublisherOptions{config.tf_publish_rate, config.transform_tolerance,
                                        config.tf_broadcast},
            [this](const ros::Time& now) { onTfTick(now); })),
        live_(config, std::move(saved), &buffer_, republisher_.get(), &warn_, nh_,
              [pnh](const PoseSaver::Record& record) { writeSavedPose(record, pnh); }),
        odometry_(config.odom_frame, config.base_frame, nh_.resolveName("odom")),
        // A dropped scan may restart the filter (a bag that starts over),
        // which takes the filter's lock; the thread that dropped it may hold
        // that lock (its map -> odom reached tf), so the main spinner handles it.
        scan_inputs_(
            scanTopics(config), cloudTopics(config), buffer_, config.odom_frame, &inline_queue_,
            [this](const sensor_msgs::LaserScanConstPtr& scan, std::size_t sensor) {
              scheduler_->onScan(
                  PendingScan{scan, ros::WallTime::now(), ros::Time::now(), sensor, nullptr});
            },
            [this](const sensor_msgs::PointCloud2ConstPtr& cloud, std::size_t sensor) {
              scheduler_->onScan(
                  PendingScan{nullptr, ros::WallTime::now(), ros::Time::now(), sensor, cloud});
            },
            [this](const std_msgs::Header& header,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
              postCallback(ros::getGlobalCallbackQueue(), reinterpret_cast<uint64_t>(this),
                           [this, header, reason] { onScanDropped(header, reason); });
            }) {
    odom_sub_ = nh_.subscribe("odom", 50, &PfNode::onOdom, this);
    tf_watch_sub_ = nh_.subscribe("/tf", 100, &PfNode::onTf, this);
    map_sub_ = nh_.subscribe("map", 1, &PfNode::onMap, this);
    initial_pose_sub_ = nh_.subscribe("initialpose", 2, &PfNode::onInitialPose, this);
    global_srv_ = nh_.advertiseService("global_localization", &PfNode::onGlobalLocalization, this);
    nomotion_srv_ =
        nh_.advertiseService("request_nomotion_update", &PfNode::onNoMotionUpdate, this);
    set_map_srv_ = nh_.advertiseService("set_map", &PfNode::onSetMap, this);
    reconfigure_ = std::make_unique<ReconfigureServer>(
        pnh_, config, [this](const LocalizerConfig& c) { return reconfigure(c); }, "pf_node");
    // Its timer or /clock on the poll thread too: it republishes when due.
    republisher_->start(withQueue(nh_, &inline_queue_));
    scheduler_ = std::make_unique<UpdateScheduler>(
        [this](const PendingScan& scan, const LatestScanSlot& slot) {
          live_.processScan(scan, slot, *reconfigure_);
        },
        [this] { return live_.nextUpdateOnPollThread(); }, &warn_);
    // Last: their callbacks may run at once, on roscpp's poll thread.
    scan_inputs_.subscribe(nh_);
  }

  ~PfNode() {
    scan_inputs_.unsubscribe();
    ros::getGlobalCallbackQueue()->removeByID(reinterpret_cast<uint64_t>(this));
    scheduler_->stop();
    republisher_.reset();  // before live_ and scheduler_ go: its onTfTick() uses them
  }

  // The main spinner: roscpp's own loop (ros::spin() waits on the queue
  // with the same 0.1 s of wall time), plus a look at Ctrl-C and at the
  // periodic save after each wait, so that no timer thread has to wake for
  // them (under simulated time a roscpp timer polls the clock every ms).
  // Ctrl-C (and roslaunch's shutdown) saves the latest pose before the node
  // goes: the periodic save may be up to 1 / save_pose_rate old. Wall
  // time: a paused bag clock must not keep Ctrl-C waiting.
  void spin() {
    ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
    while (ros::ok()) {
      queue->callAvailable(ros::WallDuration(0.1));
      PoseSaver& saver = live_.saver();
      saver.saveWhenDue(ros::Time::now());
      if (!g_sigint) continue;
      // Without a master the save would block, waiting for one.
      if (saver.enabled() && ros::master::check()) saver.saveNow();
      ros::shutdown();
    }
  }

 private:
  void onMap(const nav_msgs::OccupancyGridConstPtr& msg) {
    if (config_.first_map_only && live_.haveMap()) {
      if (warn_.due("first_map_only")) {
        ROS_INFO("pf_node: first_map_only: ignoring a new map on %s (set_map still replaces it)",
                 map_sub_.getTopic().c_str());
      }
      return;
    }
    scheduler_->withFilter([&] { live_.installMap(*msg); });
  }

  std::string reconfigure(const LocalizerConfig& next) {
    return scheduler_->withFilter([&] { return live_.reconfigure(next); });
  }

  // Odometry from the topic, for robots that have none on tf (OdometrySource).
  void onOdom(const nav_msgs::OdometryConstPtr& msg) {
    const OdometrySource::TopicMessage use = odometry_.onTopic(*msg);
    if (!use.problem.empty()) warn_.warn(use.problem_key, use.problem);
    if (use.transform) buffer_.setTransform(*use.transform, "odom_topic");
    announceOdometrySource();
  }

  // Watches /tf only until it shows whether odometry travels there.
  void onTf(const tf2_msgs::TFMessageConstPtr& msg) {
    if (!odometry_.onTf(*msg)) return;
    tf_watch_sub_.shutdown();
    // Nor is the odometry topic needed any more: unsubscribed, its
    // messages no longer wake this node (twice the scans' rate, often).
    odom_sub_.shutdown();
    announceOdometrySource();
  }

  void announceOdometrySource() {
    if (const auto line = odometry_.takeAnnouncement()) ROS_INFO("pf_node: %s", line->c_str());
  }

  void onScanDropped(const std_msgs::Header& header,
                     tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
    scheduler_->withFilter([&] { live_.scanDropped(header, reason); });
  }

  void onInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
    applyInitialPose(*msg);
  }

  bool applyInitialPose(geometry_msgs::PoseWithCovarianceStamped pose) {
    if (pose.header.frame_id.empty()) {
      warn_.warn("initialpose frame",
                 "initial pose with an empty frame_id: taken to be in " + config_.global_frame);
    } else if (pose.header.frame_id != config_.global_frame) {
      if (!transformToGlobal(&pose)) return false;
    }
    return scheduler_->withFilter([&] { return live_.setInitialPose(pose); });
  }

  // amcl's set_map: a new map and the pose on it in one call (a robot moved
  // to another floor). The map is installed even when first_map_only is set:
  // that guards against map topic updates, not against an explicit request.
  bool onSetMap(nav_msgs::SetMap::Request& req, nav_msgs::SetMap::Response& res) {
    bool installed = false;
    installed = scheduler_->withFilter([&] { return live_.installMap(req.map); });
    res.success = installed && applyInitialPose(req.initial_pose);
    return true;
  }

  // An initial pose given in another frame (say odom, or base_link) is moved
  // into the global frame through tf, covariance rotated with it.
  bool transformToGlobal(geometry_msgs::PoseWithCovarianceStamped* pose) {
    std::string error;
    const auto moved =
        poseInFrame(buffer_, *pose, config_.global_frame, ros::Duration(0.5), &error);
    if (!moved) {
      warn_.warn("initialpose tf", "ignoring the initial pose: cannot transform it from frame '" +
                                       pose->header.frame_id + "' to '" + config_.global_frame +
                                       "': " + error);
      return false;
    }
    *pose = *moved;
    return true;
  }

  bool onGlobalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    return scheduler_->withFilter([&] { return live_.startGlobalLocalization(); });
  }

  bool onNoMotionUpdate(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    scheduler_->withFilter([&] { live_.requestNoMotionUpdate(); });
    return true;
  }

  // Before each timed map -> odom (under simulated time on the poll thread,
  // from /clock), which may show time jumping back. Never waits for the
  // filter: while an update runs, the check waits for the next tick.
  void onTfTick(const ros::Time& now) {
    scheduler_->tryWithFilter([&] { live_.clockTick(now); });
  }

  const LocalizerConfig config_;  // as read: the live values are live_'s
  ros::NodeHandle nh_, pnh_;
  LimitedWarn warn_{"pf_node", kLogPeriod};
  tf2_ros::Buffer buffer_;
  InlineCallbackQueue inline_queue_;  // before every subscriber that uses it
  tf2_ros::TransformListener listener_;
  std::unique_ptr<MapToOdomRepublisher> republisher_;  // started at the end of the constructor
  LiveLocalizer live_;
  ros::Subscriber odom_sub_, map_sub_, initial_pose_sub_, tf_watch_sub_;
  OdometrySource odometry_;  // main spinner only
  ScanInputs scan_inputs_;   // after live_, which its callbacks use
  ros::ServiceServer global_srv_, nomotion_srv_, set_map_srv_;
  std::unique_ptr<ReconfigureServer> reconfigure_;
  // Guards live_ and runs the updates (started in the constructor's body).
  std::unique_ptr<UpdateScheduler> scheduler_;
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
  pf_ros::PfNode node(*config, pf_ros::readSavedPose(pnh, *config), nh, pnh);
  pf_ros::g_node_running = 1;
  node.spin();
  return 0;
}
