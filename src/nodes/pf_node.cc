// pf_node: the live ROS front door of the particle filter.
//
// Subscribes scan, odom, map (latched) and initialpose; publishes map -> odom
// on tf, the particles on particlecloud and the estimate on pf_pose and, for
// amcl's users, amcl_pose. All the localization itself happens in
// pf_ros::ScanLocalizer and the core; this file only moves messages, waits
// for tf and tells the user what is wrong. It speaks amcl's interface too
// (topics, services, parameter names, the pose saved to the parameter
// server, dynamic_reconfigure through pf_ros::ReconfigureServer), so that it
// can replace amcl in an existing bringup.
//
// Threads (README.md, "Under overload"): tf and the scans are taken on
// roscpp's own poll thread as they arrive (InlineCallbackQueue: no hand-off
// to a spinner); a scan whose tf is there goes through a one-scan
// LatestScanSlot to a filter thread of its own, so that under overload the
// newest scan wins and tf keeps being consumed; the main spinner serves the
// map, initialpose, the services, the timers and the scans tf dropped;
// map -> odom is republished by a MapToOdomRepublisher on a thread that
// never waits for the filter. filter_mutex_ protects the filter and
// everything that goes with it.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <message_filters/subscriber.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/SetMap.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "pf_localization/ros/conversions.h"
#include "pf_localization/ros/diagnostics.h"
#include "pf_localization/ros/inline_callback_queue.h"
#include "pf_localization/ros/latest_scan_slot.h"
#include "pf_localization/ros/limited_log.h"
#include "pf_localization/ros/live_params.h"
#include "pf_localization/ros/localizer_config.h"
#include "pf_localization/ros/map_to_odom_republisher.h"
#include "pf_localization/ros/reconfigure_server.h"
#include "pf_localization/ros/scan_localizer.h"
#include "pf_localization/ros/update_time_governor.h"
#include "pf_localization/ros/update_timing.h"

namespace pf_ros {
namespace {

std::string failureText(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "its stamp is older than the tf buffer";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "its frame_id is empty";
    default:
      return "no transform arrived for its stamp before the queue filled up";
  }
}

// s of odometry messages to wait for odom -> base on /tf before the odometry
// topic is taken as the source instead.
constexpr double kOdomSourceGrace = 0.5;

// How much lower the filter thread's priority is than the rest of the node
// (nice); see filterLoop().
constexpr int kFilterNiceIncrement = 5;

// s between two log lines about the same kind of bad input.
constexpr double kLogPeriod = 5.0;

// s a scan may be older than the previous one before time counts as jumping back.
constexpr double kTimeJumpTolerance = 1.0;

// s of simulated time a scan may be stamped ahead of /clock. rosbag play
// publishes /clock at 100 Hz of wall time, so at rate r the clock lags the
// messages by up to r / 100 s; a scan further ahead than this is left over
// from before time jumped back.
constexpr double kSimClockLead = 2.0;

// Set by SIGINT; the running node saves its pose, then shuts down (see main()).
volatile std::sig_atomic_t g_sigint = 0;
volatile std::sig_atomic_t g_node_running = 0;

class PfNode {
 public:
  PfNode(const LocalizerConfig& config, ros::NodeHandle nh, ros::NodeHandle pnh)
      : config_(config),
        nh_(nh),
        pnh_(pnh),
        buffer_(ros::Duration(30.0)),
        inline_queue_(ros::getGlobalCallbackQueue()),
        // tf as it arrives, with no thread of the listener's own and no
        // spinner: a transform that completes a waiting scan hands it to the
        // filter thread directly (docs/performance.md, "Wake-ups: tf and scans on the poll
        // thread").
        listener_(buffer_, withQueue(nh_, &inline_queue_), false),
        localizer_(config, &buffer_),
        governor_(UpdateTimeGovernorOptions{config.max_update_time}),
        scan_filter_(buffer_, config.odom_frame, 20, &inline_queue_) {
    scan_filter_.connectInput(scan_sub_);
    scan_filter_.registerCallback(&PfNode::onScan, this);
    // A dropped scan may restart the filter (a bag that starts over), which
    // takes filter_mutex_; the thread that dropped it may hold that mutex
    // (its map -> odom reached tf), so the main spinner handles it.
    scan_filter_.registerFailureCallback(
        [this](const sensor_msgs::LaserScanConstPtr& scan,
               tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          postCallback(ros::getGlobalCallbackQueue(), reinterpret_cast<uint64_t>(this),
                       [this, scan, reason] { onScanDropped(scan, reason); });
        });
    odom_sub_ = nh_.subscribe("odom", 50, &PfNode::onOdom, this);
    tf_watch_sub_ = nh_.subscribe("/tf", 100, &PfNode::onTf, this);
    map_sub_ = nh_.subscribe("map", 1, &PfNode::onMap, this);
    initial_pose_sub_ = nh_.subscribe("initialpose", 2, &PfNode::onInitialPose, this);
    pose_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("pf_pose", 2, true);
    // amcl's name for the same message, so that its users' tools keep working.
    amcl_pose_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("amcl_pose", 2, true);
    cloud_pub_ = nh_.advertise<geometry_msgs::PoseArray>("particlecloud", 2, true);
    // How far to trust the estimate, after every update: the standard
    // /diagnostics for robot monitors, and pf_status for anything that only
    // wants this node's verdict.
    diagnostics_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 5);
    status_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticStatus>("pf_status", 5, true);
    global_srv_ = nh_.advertiseService("global_localization", &PfNode::onGlobalLocalization, this);
    nomotion_srv_ =
        nh_.advertiseService("request_nomotion_update", &PfNode::onNoMotionUpdate, this);
    set_map_srv_ = nh_.advertiseService("set_map", &PfNode::onSetMap, this);
    republisher_ = std::make_unique<MapToOdomRepublisher>(
        MapToOdomRepublisherOptions{config.tf_publish_rate, config.transform_tolerance,
                                    config.tf_broadcast},
        [this](const ros::Time& now) { onTfTick(now); });
    if (config.save_pose_rate > 0.0) {
      save_timer_ = nh_.createTimer(ros::Duration(1.0 / config.save_pose_rate),
                                    [this](const ros::TimerEvent&) { savePose(); });
    }
    reconfigure_ = std::make_unique<ReconfigureServer>(
        pnh_, config, [this](const LocalizerConfig& c) { return reconfigure(c); }, "pf_node");
    if (config.initial_pose) {
      ROS_INFO("pf_node: initial pose (%.3f, %.3f, %.3f) in %s; waiting for a map",
               config.initial_pose->x, config.initial_pose->y, config.initial_pose->yaw,
               config.global_frame.c_str());
    } else {
      ROS_INFO("pf_node: no initial pose given: global localization once a map arrives");
    }
    republisher_->start();
    filter_thread_ = std::thread([this] { filterLoop(); });
    // Last: its callbacks may run at once, on roscpp's poll thread.
    scan_sub_.subscribe(nh_, "scan", 20, ros::TransportHints(), &inline_queue_);
  }

  ~PfNode() {
    scan_sub_.unsubscribe();
    ros::getGlobalCallbackQueue()->removeByID(reinterpret_cast<uint64_t>(this));
    slot_.close();
    filter_thread_.join();
  }

  // The main spinner: roscpp's own loop (ros::spin() waits on the queue
  // with the same 0.1 s of wall time), plus a look at Ctrl-C after each
  // wait, so that no timer thread has to wake ten times a second for it.
  // Ctrl-C (and roslaunch's shutdown) saves the latest pose before the node
  // goes: the periodic save may be up to 1 / save_pose_rate old. Wall
  // time: a paused bag clock must not keep Ctrl-C waiting.
  void spin() {
    ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
    while (ros::ok()) {
      queue->callAvailable(ros::WallDuration(0.1));
      if (!g_sigint) continue;
      // Without a master the save would block, waiting for one.
      if (config_.save_pose_rate > 0.0 && ros::master::check()) savePose();
      ros::shutdown();
    }
  }

 private:
  void onMap(const nav_msgs::OccupancyGridConstPtr& msg) {
    if (config_.first_map_only && have_map_) {
      if (log_.due("first_map_only")) {
        ROS_INFO("pf_node: first_map_only: ignoring a new map on %s (set_map still replaces it)",
                 map_sub_.getTopic().c_str());
      }
      return;
    }
    std::lock_guard<std::mutex> lock(filter_mutex_);
    installMap(*msg);
  }

  // The live parameters from ReconfigureServer: the filter's at its next
  // update, this node's own (tf and particlecloud rates, transform_tolerance) now.
  std::string reconfigure(const LocalizerConfig& next) {
    std::lock_guard<std::mutex> lock(filter_mutex_);
    const std::string error = localizer_.reconfigure(next);
    if (!error.empty()) return error;
    republisher_->setRate(next.tf_publish_rate);
    republisher_->setTransformTolerance(next.transform_tolerance);
    governor_.setMaxUpdateTime(next.max_update_time);
    copyLiveParams(next, &config_);
    applyParticleCap(governor_.cap());
    return "";
  }

  // filter_mutex_ held: max_update_time's cap on the particle count, under
  // the configured max_particles (0: none, the configured bounds alone).
  void applyParticleCap(std::size_t cap) {
    pf::ParticleFilterParams p = localizer_.config().filter;
    if (cap > 0 && cap < static_cast<std::size_t>(p.kld.max_particles)) {
      p.kld.max_particles = static_cast<int>(cap);
      p.kld.min_particles = std::min(p.kld.min_particles, p.kld.max_particles);
    }
    const pf::KldParams& now = localizer_.filter().params().kld;
    if (now.max_particles == p.kld.max_particles && now.min_particles == p.kld.min_particles)
      return;
    localizer_.filter().setParams(p);
  }

  // filter_mutex_ held.
  bool installMap(const nav_msgs::OccupancyGrid& map) {
    const std::string error = localizer_.setMap(map);
    if (!error.empty()) {
      ROS_ERROR("pf_node: %s", error.c_str());
      return false;
    }
    have_map_ = true;
    ROS_INFO("pf_node: map %u x %u cells at %.3f m; %zu particles", map.info.width, map.info.height,
             map.info.resolution, localizer_.filter().particles().size());
    publishEstimate(map.header.stamp, true);
    filterChanged(ros::Time());
    return true;
  }

  void onOdom(const nav_msgs::OdometryConstPtr& msg) {
    // Robots that publish odometry only as a topic get it into the tf buffer
    // here. When tf carries it too (the usual case) the topic is ignored:
    // tf2 would otherwise see every odometry stamp twice, and onTf
    // unsubscribes from it.
    if (msg->header.frame_id.empty() || msg->child_frame_id.empty()) {
      warn("odom frames", "odometry message with an empty frame_id or child_frame_id: ignored");
      return;
    }
    if (odom_on_tf_) return;
    // Give /tf a moment to show its odometry before taking the topic's.
    if (first_odom_stamp_.isZero()) first_odom_stamp_ = msg->header.stamp;
    if ((msg->header.stamp - first_odom_stamp_).toSec() < kOdomSourceGrace) return;
    const geometry_msgs::TransformStamped t = odometryToTransform(*msg);
    if (!toPose2(t.transform).isFinite()) {
      warn("odom nan", "odometry message with a non-finite pose: ignored");
      return;
    }
    buffer_.setTransform(t, "odom_topic");
  }

  // Watches /tf only until it shows whether odometry travels there.
  void onTf(const tf2_msgs::TFMessageConstPtr& msg) {
    for (const auto& t : msg->transforms) {
      if (t.header.frame_id == config_.odom_frame && t.child_frame_id == config_.base_frame) {
        odom_on_tf_ = true;
        tf_watch_sub_.shutdown();
        // Nor is the odometry topic needed any more: unsubscribed, its
        // messages no longer wake this node (twice the scans' rate, often).
        odom_sub_.shutdown();
        ROS_INFO("pf_node: odometry %s -> %s comes from tf", config_.odom_frame.c_str(),
                 config_.base_frame.c_str());
        return;
      }
    }
  }

  // Once tf has the scan's stamp, on whichever thread brought the scan or
  // the transform that completed it (InlineCallbackQueue): only hands the
  // scan to the filter thread, so that no thread waits here for an update.
  void onScan(const sensor_msgs::LaserScanConstPtr& scan) {
    if (!slot_.put(PendingScan{scan, ros::WallTime::now(), ros::Time::now()})) return;
    const std::uint64_t dropped = slot_.dropped();
    warn("overload",
         "the filter cannot keep up: a scan waiting for it was dropped for a newer one (" +
             std::to_string(dropped) +
             " since start; see dropped_scans and latency_* in the diagnostics). Lower "
             "max_particles, or set max_update_time");
  }

  // The filter thread: the newest waiting scan, one at a time.
  void filterLoop() {
    // The filter yields the CPU to this node's other threads (map -> odom,
    // odometry and tf, the clock): a lower priority for this thread and
    // the threads it starts (OpenMP's, with sensor_threads > 1). Raising
    // the nice value needs no privilege; failing, it changes nothing.
    const id_t tid = static_cast<id_t>(::syscall(SYS_gettid));
    errno = 0;
    const int nice = ::getpriority(PRIO_PROCESS, tid);
    if (errno == 0) ::setpriority(PRIO_PROCESS, tid, std::min(19, nice + kFilterNiceIncrement));
    // The destructor's close() wakes the wait; its time-out only bounds how
    // long a shutdown by another way goes unseen (a shorter one would wake
    // an idle node ten times a second for nothing).
    while (ros::ok() && !slot_.closed()) {
      if (auto pending = slot_.take(ros::WallDuration(1.0))) processScan(*pending);
    }
  }

  void processScan(const PendingScan& pending) {
    const sensor_msgs::LaserScan& scan = *pending.scan;
    std::lock_guard<std::mutex> lock(filter_mutex_);
    if (fromBeforeTheJump(scan.header.stamp)) return;
    if (timeJumpedBack(scan.header.stamp)) return;
    const ros::WallTime start = ros::WallTime::now();
    const ScanResult result = localizer_.processScan(scan);
    const double update_s = (ros::WallTime::now() - start).toSec();
    if (result.error != pf_ros::ScanError::kNone) {
      warn(pf_ros::toString(result.error), pf_ros::errorMessage(result));
      return;
    }
    if (!result.warning.empty()) warn("scan inconsistent", result.warning);
    const pf::UpdateReport& r = result.report;
    last_odom_ = result.odom;
    last_scan_stamp_ = scan.header.stamp;
    // map -> odom first: tf users wait for it, nobody waits for the rest.
    filterChanged(scan.header.stamp);
    if (r.updated) {
      timing_.addUpdate((ros::WallTime::now() - pending.arrival_wall).toSec(),
                        (pending.arrival_clock - scan.header.stamp).toSec(), update_s);
      if (governor_.enabled()) applyParticleCap(governor_.addUpdate(r.particles, update_s));
      publishEstimate(scan.header.stamp, false);
      publishConfidence(scan.header.stamp, r);
      ROS_DEBUG("pf_node: update with %d beams, %zu particles, ESS %.0f%s in %.1f ms", r.beams_used,
                r.particles, r.ess, r.resampled ? ", resampled" : "", update_s * 1e3);
    } else if (r.skip_reason != pf::SkipReason::kNotMoved) {
      warn(pf::toString(r.skip_reason), "scan not used: " + pf::skipMessage(r));
    }
  }

  // A scan older than the previous one by more than a second means time
  // went back (a bag restarted, with --loop or by hand): tf data and the
  // filter's odometry reference belong to the old timeline, so both start
  // over, as tf itself does on such a jump.
  bool timeJumpedBack(const ros::Time& stamp, double tolerance = kTimeJumpTolerance) {
    if (last_scan_stamp_.isZero() || stamp + ros::Duration(tolerance) >= last_scan_stamp_) {
      return false;
    }
    ROS_WARN(
        "pf_node: time jumped back by %.1f s (a bag restarted?): clearing tf and restarting "
        "the filter %s",
        (last_scan_stamp_ - stamp).toSec(),
        config_.initial_pose ? "from the initial pose" : "with global localization");
    buffer_.clear();
    last_odom_.reset();
    const std::string error = localizer_.restart();
    if (!error.empty()) ROS_WARN("pf_node: %s", error.c_str());
    last_scan_stamp_ = ros::Time();
    republisher_->reset();
    filterChanged(ros::Time());
    return true;
  }

  // How far `stamp` lies ahead of /clock, when it is further ahead than the
  // clock's normal lag (kSimClockLead); nothing with wall time or a clock
  // that has not started.
  static std::optional<double> aheadOfSimClock(const ros::Time& stamp) {
    if (!ros::Time::isSimTime()) return std::nullopt;
    const ros::Time now = ros::Time::now();
    if (now.isZero() || stamp <= now + ros::Duration(kSimClockLead)) return std::nullopt;
    return (stamp - now).toSec();
  }

  // When a bag starts over, messages of the old timeline are still queued in
  // this node's subscriptions and tf's: they arrive after the jump back, stamped
  // ahead of the clock. A scan among them would restart the filter a second
  // time, at the wrong place; they are dropped instead. Only under simulated
  // time: with wall time, a scan ahead of the clock means unsynchronised
  // computers, and dropping all of them would be worse.
  bool fromBeforeTheJump(const ros::Time& stamp) {
    const auto ahead = aheadOfSimClock(stamp);
    if (!ahead) return false;
    warn("scan ahead of clock", "scan ignored: stamped " + std::to_string(*ahead) +
                                    " s ahead of /clock, so it is from before time jumped back");
    return true;
  }

  // The same leftovers on tf: an old-timeline transform that reached the
  // buffer after it was cleared holds its frame's time far ahead, and tf2
  // then refuses every new transform of that frame as too old for its cache
  // (TF_OLD_DATA), which would drop the scans for the length of the cache.
  // A link of the scan's chain (odometry, or the laser's mounting) stamped
  // ahead of /clock shows exactly that, and the buffer is cleared again.
  void clearStaleBuffer(const std::string& laser_frame) {
    ros::Time latest;
    for (const auto& [parent, child] : {std::pair{config_.odom_frame, config_.base_frame},
                                        std::pair{config_.base_frame, laser_frame}}) {
      try {
        latest =
            std::max(latest, buffer_.lookupTransform(parent, child, ros::Time(0)).header.stamp);
      } catch (const tf2::TransformException&) {
        // A link missing altogether is not this problem; the drop says so.
      }
    }
    const auto ahead = aheadOfSimClock(latest);
    if (!ahead) return;
    warn("stale tf", "clearing tf again: it still held transforms from before time jumped back (" +
                         std::to_string(*ahead) + " s ahead of /clock)");
    buffer_.clear();
  }

  void onScanDropped(const sensor_msgs::LaserScanConstPtr& scan,
                     tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
    std::lock_guard<std::mutex> lock(filter_mutex_);
    // The first scans after a bag starts over often land here as older than
    // the buffer, which still holds the old timeline: the jump back is
    // detected on them too, so that the filter restarts on the first scan of
    // the new timeline. (Not on scans dropped from a full queue: those are
    // the oldest waiting, legitimately older than the last scan used.)
    if (ros::Time::isSimTime()) {
      if (reason == tf2_ros::filter_failure_reasons::OutTheBack &&
          timeJumpedBack(scan->header.stamp)) {
        return;
      }
      if (!scan->header.frame_id.empty()) clearStaleBuffer(scan->header.frame_id);
    }
    warn("scan dropped " + scan->header.frame_id,
         "scan dropped: " + failureText(reason) + ". It needs tf from '" + scan->header.frame_id +
             "' to '" + config_.base_frame + "' (the laser's mounting) and '" + config_.base_frame +
             "' to '" + config_.odom_frame + "' (odometry) at t=" +
             std::to_string(scan->header.stamp.toSec()) + "; check that both are published");
  }

  void onInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
    applyInitialPose(*msg);
  }

  bool applyInitialPose(geometry_msgs::PoseWithCovarianceStamped pose) {
    if (pose.header.frame_id.empty()) {
      warn("initialpose frame",
           "initial pose with an empty frame_id: taken to be in " + config_.global_frame);
    } else if (pose.header.frame_id != config_.global_frame) {
      if (!transformToGlobal(&pose)) return false;
    }
    std::lock_guard<std::mutex> lock(filter_mutex_);
    const std::string error = localizer_.setInitialPose(pose);
    if (!error.empty()) {
      warn("initialpose", error);
      return false;
    }
    const pf::Pose2 p = toPose2(pose.pose.pose);
    ROS_INFO("pf_node: re-initialised at (%.3f, %.3f, %.3f) in %s", p.x, p.y, p.yaw,
             config_.global_frame.c_str());
    publishEstimate(pose.header.stamp, true);
    filterChanged(ros::Time());
    return true;
  }

  // amcl's set_map: a new map and the pose on it in one call (a robot moved
  // to another floor). The map is installed even when first_map_only is set:
  // that guards against map topic updates, not against an explicit request.
  bool onSetMap(nav_msgs::SetMap::Request& req, nav_msgs::SetMap::Response& res) {
    bool installed = false;
    {
      std::lock_guard<std::mutex> lock(filter_mutex_);
      installed = installMap(req.map);
    }
    res.success = installed && applyInitialPose(req.initial_pose);
    return true;
  }

  // An initial pose given in another frame (say odom, or base_link) is moved
  // into the global frame through tf, covariance rotated with it.
  bool transformToGlobal(geometry_msgs::PoseWithCovarianceStamped* pose) {
    geometry_msgs::TransformStamped t;
    try {
      t = buffer_.lookupTransform(config_.global_frame, pose->header.frame_id, ros::Time(0),
                                  ros::Duration(0.5));
    } catch (const tf2::TransformException& e) {
      warn("initialpose tf", "ignoring the initial pose: cannot transform it from frame '" +
                                 pose->header.frame_id + "' to '" + config_.global_frame +
                                 "': " + e.what());
      return false;
    }
    const pf::Pose2 frame = toPose2(t.transform);
    pose->pose.pose = toPoseMsg(pf::compose(frame, toPose2(pose->pose.pose)));
    Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
    rot.topLeftCorner<2, 2>() << std::cos(frame.yaw), -std::sin(frame.yaw), std::sin(frame.yaw),
        std::cos(frame.yaw);
    pose->pose.covariance =
        toRosCovariance(rot * fromRosCovariance(pose->pose.covariance) * rot.transpose());
    pose->header.frame_id = config_.global_frame;
    return true;
  }

  bool onGlobalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    std::lock_guard<std::mutex> lock(filter_mutex_);
    const std::string error = localizer_.startGlobalLocalization();
    if (!error.empty()) {
      ROS_WARN("pf_node: %s", error.c_str());
      return false;
    }
    ROS_INFO("pf_node: global localization: %zu particles over the free space",
             localizer_.filter().particles().size());
    publishEstimate(ros::Time::now(), true);
    filterChanged(ros::Time());
    return true;
  }

  bool onNoMotionUpdate(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    std::lock_guard<std::mutex> lock(filter_mutex_);
    localizer_.filter().requestNoMotionUpdate();
    return true;
  }

  // On the republishing thread, before each timed map -> odom. Under
  // simulated time the clock itself shows a bag starting over, often before
  // any scan of the new timeline gets through tf. (It lags the messages a
  // little, hence the wider tolerance.) Never waits for the filter: while an
  // update runs, the check waits for the next tick.
  void onTfTick(const ros::Time& now) {
    if (!ros::Time::isSimTime()) return;
    std::unique_lock<std::mutex> lock(filter_mutex_, std::try_to_lock);
    if (lock.owns_lock()) timeJumpedBack(now, kSimClockLead);
  }

  void publishConfidence(const ros::Time& stamp, const pf::UpdateReport& report) {
    const std::string name = ros::this_node::getName() + ": localization";
    diagnostic_msgs::DiagnosticArray array;
    array.header.stamp = stamp;
    array.status.push_back(
        toDiagnosticStatus(localizer_.filter(), report, name, reconfigure_->generation()));
    timing_.addTo(&array.status.front(), slot_.dropped(), governor_.cap());
    diagnostics_pub_.publish(array);
    status_pub_.publish(array.status.front());
    // A change of state is news; the same state on every scan is not.
    const pf::Confidence& c = localizer_.filter().confidence();
    if (c.state == last_state_) return;
    last_state_ = c.state;
    if (c.state == pf::LocalizationState::kLocalized) {
      ROS_INFO("pf_node: localized: %s", c.reason.c_str());
    } else {
      ROS_WARN("pf_node: %s: %s", pf::toString(c.state), c.reason.c_str());
    }
  }

  // `always`: a re-initialisation, shown even when gui_publish_rate would
  // hold the cloud back (that limit is for the stream of updates). The cloud
  // is only built for a subscriber, and at most cloud_max_poses poses of it.
  void publishEstimate(const ros::Time& stamp, bool always) {
    if (const auto pose = localizer_.estimate(stamp)) {
      pose_pub_.publish(*pose);
      amcl_pose_pub_.publish(*pose);
    }
    const double period = config_.gui_publish_rate > 0.0 ? 1.0 / config_.gui_publish_rate : 0.0;
    const bool due = always || last_cloud_stamp_.isZero() || stamp < last_cloud_stamp_ ||
                     (stamp - last_cloud_stamp_).toSec() >= period;
    if (!due || cloud_pub_.getNumSubscribers() == 0) return;
    cloud_pub_.publish(
        localizer_.particleCloud(stamp, static_cast<std::size_t>(config_.cloud_max_poses)));
    last_cloud_stamp_ = stamp;
  }

  // filter_mutex_ held, after anything that moved the filter: map -> odom
  // goes to the republisher and the pose to the saver, neither of which
  // may wait for the filter (an update can hold it for longer than a scan
  // period: a saver on the main spinner that waited would hold back the
  // scans and odometry queued behind it).
  void filterChanged(const ros::Time& scan_stamp) {
    republisher_->set(localizer_.mapToOdom(ros::Time()), scan_stamp);
    if (config_.save_pose_rate <= 0.0) return;  // nothing is ever saved
    std::optional<PoseToSave> next;
    if (const auto estimate = localizer_.estimate(ros::Time())) {
      // The estimate is as old as the last filter update; the odometry of
      // the latest scan (used or not) carries it to the robot's pose then.
      pf::Pose2 pose = toPose2(estimate->pose.pose);
      const auto map_to_odom = localizer_.filter().mapToOdom();
      if (map_to_odom && last_odom_) pose = pf::compose(*map_to_odom, *last_odom_);
      if (pose.isFinite()) {
        next = PoseToSave{pose, estimate->pose.covariance[0], estimate->pose.covariance[7],
                          estimate->pose.covariance[35]};
      }
    }
    std::lock_guard<std::mutex> lock(save_mutex_);
    pose_to_save_ = next;
  }

  // As amcl does: the pose goes to ~initial_pose_* and its variances to
  // ~initial_cov_*, where readConfig finds them, so that a node restarted
  // under the same master (respawn, a crash, a relaunch of this node alone)
  // resumes where the robot is instead of starting over.
  void savePose() {
    std::optional<PoseToSave> saved;
    {
      std::lock_guard<std::mutex> lock(save_mutex_);
      saved = pose_to_save_;
    }
    if (!saved) return;
    pnh_.setParam("initial_pose_x", saved->pose.x);
    pnh_.setParam("initial_pose_y", saved->pose.y);
    pnh_.setParam("initial_pose_a", saved->pose.yaw);
    pnh_.setParam("initial_cov_xx", saved->cov_xx);
    pnh_.setParam("initial_cov_yy", saved->cov_yy);
    pnh_.setParam("initial_cov_aa", saved->cov_aa);
  }

  void warn(const std::string& key, const std::string& text) {
    int suppressed = 0;
    if (!log_.due(key, &suppressed)) return;
    if (suppressed > 0) {
      ROS_WARN("pf_node: %s (%d more like it since the last such line)", text.c_str(), suppressed);
    } else {
      ROS_WARN("pf_node: %s", text.c_str());
    }
  }

  LocalizerConfig config_;
  ros::NodeHandle nh_, pnh_;
  tf2_ros::Buffer buffer_;
  InlineCallbackQueue inline_queue_;  // before every subscriber that uses it
  tf2_ros::TransformListener listener_;
  // Guards localizer_, config_, governor_ and the state below that goes
  // with the filter (last_odom_, last_state_, last_scan_stamp_,
  // last_cloud_stamp_): taken by the filter thread for a whole update, and
  // by the main spinner's callbacks that touch the filter. The republisher
  // never waits for it.
  std::mutex filter_mutex_;
  ScanLocalizer localizer_;
  UpdateTimeGovernor governor_;
  UpdateTiming timing_;
  LatestScanSlot slot_;
  message_filters::Subscriber<sensor_msgs::LaserScan> scan_sub_;
  tf2_ros::MessageFilter<sensor_msgs::LaserScan> scan_filter_;
  ros::Subscriber odom_sub_, map_sub_, initial_pose_sub_, tf_watch_sub_;
  bool odom_on_tf_ = false;
  bool have_map_ = false;
  ros::Time first_odom_stamp_;
  std::optional<pf::Pose2> last_odom_;  // odom -> base at the latest scan used
  ros::Publisher pose_pub_, amcl_pose_pub_, cloud_pub_, diagnostics_pub_, status_pub_;
  std::optional<pf::LocalizationState> last_state_;
  ros::ServiceServer global_srv_, nomotion_srv_, set_map_srv_;
  ros::Timer save_timer_;
  // The pose savePose() writes, kept by filterChanged(): its own small lock,
  // so that the saver never waits for an update.
  struct PoseToSave {
    pf::Pose2 pose;
    double cov_xx, cov_yy, cov_aa;
  };
  std::mutex save_mutex_;
  std::optional<PoseToSave> pose_to_save_;
  ros::Time last_scan_stamp_, last_cloud_stamp_;
  LimitedLog log_{kLogPeriod};
  std::unique_ptr<ReconfigureServer> reconfigure_;
  std::unique_ptr<MapToOdomRepublisher> republisher_;
  std::thread filter_thread_;  // last: started when everything else exists
};

}  // namespace
}  // namespace pf_ros

int main(int argc, char** argv) {
  // roscpp's own SIGINT handler would shut down before the pose is saved.
  ros::init(argc, argv, "pf_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, [](int) {
    pf_ros::g_sigint = 1;
    // Before the node runs (waiting for a master, say) there is nothing to
    // save: stop at once, as roscpp's handler does.
    if (!pf_ros::g_node_running) ros::requestShutdown();
  });
  ros::NodeHandle nh, pnh("~");
  pf_ros::LocalizerConfig config;
  try {
    // ~defaults (launch/amcl_compatible.launch loads config/pf.yaml there)
    // sits under everything else, so that amcl's names in ~ override it.
    std::unique_ptr<pf_ros::ParamSource> defaults;
    if (pnh.hasParam("defaults"))
      defaults = pf_ros::rosParamSource(ros::NodeHandle(pnh, "defaults"));
    pf_ros::ConfigNotes notes;
    config = pf_ros::readConfig(*pf_ros::rosParamSource(pnh), defaults.get(), &notes);
    for (const std::string& w : notes.warnings) ROS_WARN("pf_node: %s", w.c_str());
    for (const std::string& i : notes.infos) ROS_INFO("pf_node: %s", i.c_str());
  } catch (const std::exception& e) {
    ROS_FATAL("pf_node: refusing to start: %s", e.what());
    return 1;
  }
  pf_ros::PfNode node(config, nh, pnh);
  pf_ros::g_node_running = 1;
  node.spin();
  return 0;
}
