#include "pf_localization/ros/localizer/live_localizer.h"

#include <algorithm>
#include <utility>

#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/input/pose_transform.h"
#include "pf_localization/ros/input/scan_drop_message.h"

namespace pf_ros {
namespace {

// ros::Time::now(), asked only under simulated time, where it matters.
ros::Time simClockNow() { return ros::Time::isSimTime() ? ros::Time::now() : ros::Time(); }

}  // namespace

LiveLocalizer::LiveLocalizer(const LocalizerConfig& config, std::optional<SavedPoseMap> saved,
                             tf2_ros::Buffer* tf, MapToOdomRepublisher* republisher,
                             LimitedWarn* warn, ros::NodeHandle& nh, PoseSaver::Write write_pose)
    : config_(config),
      tf_(tf),
      republisher_(republisher),
      warn_(warn),
      localizer_(config, tf),
      governor_(UpdateTimeGovernorOptions{config.max_update_time}),
      output_(nh),
      jumps_(tf, config.odom_frame, config.base_frame, warn,
             [this](double back_s) { restartAfterJump(back_s); }),
      changes_saver_(config.map_changes_file.empty()
                         ? defaultMapChangesPath(ros::this_node::getName())
                         : config.map_changes_file,
                     config.save_pose_rate),
      saver_(config.save_pose_rate,
             [this, write_pose = std::move(write_pose)](const PoseSaver::Record& record) {
               if (write_pose) write_pose(record);
               writeMapChanges();
             }),
      saved_pose_(std::move(saved)) {
  logInitialPose();
}

void LiveLocalizer::logInitialPose() const {
  if (!config_.initial_pose) {
    ROS_INFO("pf_node: no initial pose given: global localization once a map arrives");
    return;
  }
  const pf::Pose2& p = *config_.initial_pose;
  ROS_INFO("pf_node: initial pose (%.3f, %.3f, %.3f) in %s%s; waiting for a map", p.x, p.y, p.yaw,
           config_.global_frame.c_str(),
           saved_pose_ ? ", saved by an earlier run: used only on the map it was saved on" : "");
}

bool LiveLocalizer::installMap(const nav_msgs::OccupancyGrid& map, UpdateScheduler& scheduler) {
  BuiltMap built = buildMap(map, scheduler);
  return scheduler.withFilter([&] { return install(std::move(built), map.header.stamp); });
}

void LiveLocalizer::mapFromTopic(const nav_msgs::OccupancyGrid& map, const std::string& topic,
                                 UpdateScheduler& scheduler) {
  if (floor_search_ || (config_.first_map_only && have_map_)) {
    if (warn_->due("first_map_only")) {
      ROS_INFO("pf_node: %s: ignoring a new map on %s",
               floor_search_ ? "floors_file" : "first_map_only", topic.c_str());
    }
    return;
  }
  installMap(map, scheduler);
}

bool LiveLocalizer::applyInitialPose(const geometry_msgs::PoseWithCovarianceStamped& pose,
                                     UpdateScheduler& scheduler) {
  const auto global = initialPoseInFrame(*tf_, pose, config_.global_frame, warn_);
  return global && scheduler.withFilter([&] { return setInitialPose(*global); });
}

bool LiveLocalizer::setMap(nav_msgs::SetMap::Request& request, UpdateScheduler& scheduler) {
  if (request.initial_pose.header.stamp.isZero())
    request.initial_pose.header.stamp = ros::Time::now();
  if (floor_search_) {
    ROS_WARN("pf_node: set_map refused: the maps are floors_file's (change_floor)");
    return false;
  }
  return installMap(request.map, scheduler) && applyInitialPose(request.initial_pose, scheduler);
}

bool LiveLocalizer::globalLocalization(UpdateScheduler& scheduler) {
  if (floor_search_) floor_search_();
  return scheduler.withFilter([&] { return startGlobalLocalization(); });
}

LiveLocalizer::BuiltMap LiveLocalizer::buildMap(const nav_msgs::OccupancyGrid& map,
                                                UpdateScheduler& scheduler) const {
  const auto recipe = scheduler.withFilter([&] { return localizer_.mapRecipe(); });
  BuiltMap built{ScanLocalizer::prepareMap(map, recipe), ""};
  // The checksum of the map's cells (48 MB on a 200 x 600 m floor) only for
  // a saver or a saved pose to check.
  if (built.ready.map && (config_.save_pose_rate > 0.0 || saved_pose_.has_value())) {
    built.signature = mapSignature(map);
  }
  return built;
}

bool LiveLocalizer::changeFloor(std::optional<BuiltMap> built, const std::string& floor,
                                const std::optional<geometry_msgs::PoseWithCovarianceStamped>& pose,
                                std::optional<pf::PreparedMap>* replaced) {
  const ros::Time stamp = pose ? pose->header.stamp : ros::Time::now();
  // A first map without a pose starts as any first map does: from the
  // configured initial pose (or a saved one, checked), or globally.
  const bool starts = !have_map_ && !pose;
  if (built && !install(std::move(*built), stamp, floor, replaced, starts)) return false;
  output_.setFloor(floor);
  if (starts) return true;
  if (!pose) return startGlobalLocalization();
  if (setInitialPose(*pose)) return true;
  // Refused (warned): not the old floor's particles on this floor's map.
  startGlobalLocalization();
  return false;
}

bool LiveLocalizer::install(BuiltMap built, const ros::Time& stamp, const std::string& floor,
                            std::optional<pf::PreparedMap>* replaced, bool announce) {
  const bool first = !have_map_;
  const nav_msgs::MapMetaData info = built.ready.info;
  const std::string& signature = built.signature;
  // The floor left: its layer's last copy, for its own file.
  if (!floor.empty() && !first) {
    changes_saver_.offer(localizer_.mapChanges(), ros::WallTime::now(), true);
  }
  const std::string error = localizer_.setMap(std::move(built.ready), replaced);
  if (!error.empty()) {
    ROS_ERROR("pf_node: %s", error.c_str());
    return false;
  }
  have_map_ = true;
  placement_.reset();
  if (config_.save_pose_rate > 0.0 || (first && saved_pose_)) {
    saver_.setMap(signature, floor);
    if (first && saved_pose_) checkSavedPose(signature, floor);
  }
  // A floor's layer is restored with its map's first build, a single map's on the first map.
  if (changes_saver_.enabled()) {
    mapChangesOnNewMap(signature, floor, floor.empty() ? first : !built.kept, stamp);
  }
  ROS_INFO("pf_node: map %u x %u cells at %.3f m; %zu particles", info.width, info.height,
           info.resolution, localizer_.filter().particles().size());
  if (!announce) return true;
  output_.publishEstimate(localizer_, stamp, true);
  filterChanged(ros::Time());
  return true;
}

// On the first map, when the configured initial pose was saved by an
// earlier run: it stays only on the map (and floor) it was saved on, in free
// space; otherwise global localization, now and on a restart.
void LiveLocalizer::checkSavedPose(const std::string& map_signature, const std::string& floor) {
  const SavedPoseDecision d = decideSavedPose(*saved_pose_, *config_.initial_pose, map_signature,
                                              *localizer_.filter().map(), floor);
  saved_pose_.reset();
  if (d.resume) {
    ROS_INFO("pf_node: %s", d.message.c_str());
    return;
  }
  ROS_WARN("pf_node: %s", d.message.c_str());
  saved_pose_ignored_ = true;
  // An initial pose that came before the map is what the filter started from.
  if (pose_before_map_) return;
  const std::string error = localizer_.startGlobalLocalization();
  if (!error.empty()) ROS_WARN("pf_node: %s", error.c_str());
}

void LiveLocalizer::mapChangesOnNewMap(const std::string& signature, const std::string& floor,
                                       bool restore, const ros::Time& stamp) {
  const std::string path =
      floor.empty() ? changes_saver_.path() : floorMapChangesPath(changes_saver_.path(), floor);
  // A kept floor's layer is as its file holds it, or as a pending copy will.
  const pf::MapChangeLayer* layer = localizer_.mapChanges();
  changes_saver_.setMap(signature, restore || !layer ? 0 : layer->scans(), path);
  if (!restore) return;
  const MapChangesRestore r = restoreMapChanges(path, signature, &localizer_.filter());
  const std::string on = floor.empty() ? "" : "floor '" + floor + "': ";
  if (r.level == MapChangesRestore::Level::kWarn) {
    ROS_WARN("pf_node: %s%s", on.c_str(), r.message.c_str());
  } else {
    ROS_INFO("pf_node: %s%s", on.c_str(), r.message.c_str());
  }
  if (!r.restored) return;
  changes_saver_.setMap(signature, localizer_.mapChanges()->scans(), path);  // the file holds it
  output_.publishMapChangesNow(localizer_, stamp);
}

bool LiveLocalizer::clearMapChanges() {
  if (!have_map_) return false;
  const std::size_t changed =
      localizer_.mapChanges()->summary().added + localizer_.mapChanges()->summary().removed;
  localizer_.filter().clearMapChanges();
  changes_saver_.changed();
  output_.publishMapChangesNow(localizer_, ros::Time::now());
  ROS_INFO("pf_node: map changes cleared (%zu cells were new or gone)%s", changed,
           changes_saver_.enabled() ? "; the file follows at the next save" : "");
  return true;
}

void LiveLocalizer::saveAtShutdown(UpdateScheduler& scheduler) {
  if (!saver_.enabled()) return;
  scheduler.withFilter(
      [&] { changes_saver_.offer(localizer_.mapChanges(), ros::WallTime::now(), true); });
  // Without a master the pose's save would block, waiting for one.
  if (ros::master::check()) saver_.saveNow();
  writeMapChanges();  // when there was no pose to save with it
}

void LiveLocalizer::writeMapChanges() {
  const std::string error = changes_saver_.writePending();
  if (!error.empty()) warn_->warn("map changes file", "the map changes are not saved: " + error);
}

bool LiveLocalizer::setInitialPose(const geometry_msgs::PoseWithCovarianceStamped& pose) {
  const std::string error = localizer_.setInitialPose(pose);
  if (!error.empty()) {
    warn_->warn("initialpose", error);
    return false;
  }
  if (!have_map_) pose_before_map_ = true;
  const pf::Pose2 p = *localizer_.config().initial_pose;  // moved on by the odometry since
  ROS_INFO("pf_node: re-initialised at (%.3f, %.3f, %.3f) in %s", p.x, p.y, p.yaw,
           config_.global_frame.c_str());
  output_.publishEstimate(localizer_, pose.header.stamp, true);
  filterChanged(ros::Time());
  return true;
}

bool LiveLocalizer::startGlobalLocalization() {
  const std::string error = localizer_.startGlobalLocalization();
  if (!error.empty()) {
    ROS_WARN("pf_node: %s", error.c_str());
    return false;
  }
  ROS_INFO("pf_node: global localization: %zu particles over the free space",
           localizer_.filter().particles().size());
  output_.publishEstimate(localizer_, ros::Time::now(), true);
  filterChanged(ros::Time());
  return true;
}

std::string LiveLocalizer::reconfigure(const LocalizerConfig& next) {
  const std::string error = localizer_.reconfigure(next);
  if (!error.empty()) return error;
  republisher_->setRate(next.tf_publish_rate);
  republisher_->setTransformTolerance(next.transform_tolerance);
  governor_.setMaxUpdateTime(next.max_update_time);
  applyParticleCap(governor_.cap());
  return "";
}

// max_update_time's cap on the particle count, under the configured
// max_particles (0: none, the configured bounds alone).
void LiveLocalizer::applyParticleCap(std::size_t cap) {
  pf::ParticleFilterParams p = localizer_.config().filter;
  if (cap > 0 && cap < static_cast<std::size_t>(p.kld.max_particles)) {
    p.kld.max_particles = static_cast<int>(cap);
    p.kld.min_particles = std::min(p.kld.min_particles, p.kld.max_particles);
  }
  const pf::KldParams& now = localizer_.filter().params().kld;
  if (now.max_particles == p.kld.max_particles && now.min_particles == p.kld.min_particles) return;
  localizer_.filter().setParams(p);
}

void LiveLocalizer::processScan(const PendingScan& pending, const LatestScanSlot& slot,
                                const ReconfigureServer& reconfigure) {
  const std_msgs::Header& header = pending.header();
  if (!jumps_.admitScan(header.stamp, simClockNow(), ros::Time::isSimTime())) return;
  const std::size_t weighed = localizer_.filter().particles().size();
  const ros::WallTime start = ros::WallTime::now();
  const ScanResult result = pending.scan ? localizer_.processScan(*pending.scan, pending.sensor)
                                         : localizer_.processCloud(*pending.cloud, pending.sensor);
  const double update_s = (ros::WallTime::now() - start).toSec();
  if (result.error != ScanError::kNone) {
    warn_->warn(toString(result.error), errorMessage(result));
    return;
  }
  if (!result.warning.empty()) warn_->warn("scan inconsistent", result.warning);
  const pf::UpdateReport& r = result.report;
  const ros::Time& stamp = header.stamp;
  last_odom_ = result.odom;
  jumps_.scanUsed(stamp);
  // map -> odom first: tf users wait for it, nobody waits for the rest.
  filterChanged(stamp);
  if (r.updated) {
    timing_.addUpdate((ros::WallTime::now() - pending.arrival_wall).toSec(),
                      (pending.arrival_clock - stamp).toSec(), update_s);
    placement_.addUpdate(update_s, weighed);
    if (governor_.enabled()) applyParticleCap(governor_.addUpdate(r.particles, update_s));
    output_.publishEstimate(localizer_, stamp, false);
    output_.publishConfidence(localizer_, stamp, r, reconfigure.generation(), timing_,
                              slot.dropped(), governor_.cap());
    ROS_DEBUG("pf_node: update with %d beams, %zu particles, ESS %.0f%s in %.1f ms", r.beams_used,
              r.particles, r.ess, r.resampled ? ", resampled" : "", update_s * 1e3);
  } else if (r.skip_reason != pf::SkipReason::kNotMoved) {
    warn_->warn(pf::toString(r.skip_reason), "scan not used: " + pf::skipMessage(r));
  }
}

// tf (cleared by then) and the filter's odometry reference belong to the old
// timeline, so both start over, as tf itself does on such a jump: from the
// initial pose, or with global localization.
void LiveLocalizer::restartAfterJump(double back_s) {
  const bool from_pose = config_.initial_pose && !saved_pose_ignored_;
  ROS_WARN(
      "pf_node: time jumped back by %.1f s (a bag restarted?): clearing tf and restarting "
      "the filter %s",
      back_s, from_pose ? "from the initial pose" : "with global localization");
  last_odom_.reset();
  std::string error = localizer_.restart();
  // restart() goes back to the configured pose, which was a saved one not to use.
  if (error.empty() && !from_pose && config_.initial_pose) {
    error = localizer_.startGlobalLocalization();
  }
  if (!error.empty()) ROS_WARN("pf_node: %s", error.c_str());
  republisher_->reset();
  filterChanged(ros::Time());
}

void LiveLocalizer::scanDropped(const std_msgs::Header& header,
                                tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  jumps_.scanDropped(header, simClockNow(), ros::Time::isSimTime());
  warn_->warn("scan dropped " + header.frame_id,
              scanDropMessage(header, reason, config_.base_frame, config_.odom_frame));
}

void LiveLocalizer::clockTick(const ros::Time& now) {
  jumps_.clockTick(now, ros::Time::isSimTime());
}

// After anything that moved the filter: map -> odom goes to the republisher
// and the pose to the saver, neither of which may wait for the filter (an
// update can hold it for longer than a scan period: a saver on the main
// spinner that waited would hold back the scans and odometry queued behind it).
void LiveLocalizer::filterChanged(const ros::Time& scan_stamp) {
  republisher_->set(localizer_.mapToOdom(ros::Time()), scan_stamp);
  if (!saver_.enabled()) return;  // nothing is ever saved
  saver_.set(poseToSave(localizer_, last_odom_));
  changes_saver_.offer(localizer_.mapChanges(), ros::WallTime::now());
}

}  // namespace pf_ros
