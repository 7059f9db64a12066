// The filter side of pf_node: the ScanLocalizer and everything that changes
// with it. A scan's update and what follows it (map -> odom to the
// republisher, the pose to the saver, the estimate and the diagnostics),
// maps, initial poses and the services, the live parameters with
// max_update_time's particle cap, time jumping back (TimeJumpHandler: tf
// and the filter start over), the scans tf dropped and the check of a pose
// saved by an earlier run on the first map (saved_pose.h), and the layer of
// the map's changes saved with the pose, restored on the first map (with a
// building's floors: on each floor's first) when it was learned on it, and
// cleared on request (map_changes_saver.h).
//
// Threads (docs/ros-interface.md, "Threads, latency and overload"): every
// method but saver(), haveMap(), installMap(), buildMap(), saveAtShutdown()
// and the main spinner's map sources, initial poses and global_localization
// (useFloors() to globalLocalization()) must be called with the filter's lock
// held (UpdateScheduler); an update holds it whole (on the filter thread, or
// on roscpp's poll thread when it is short), the main spinner's callbacks
// that touch the filter wait for it; those methods take it themselves when
// they touch the filter (installMap() and buildMap() only to read the recipe
// and, for installMap(), around the swap of a map built without it, and
// saveAtShutdown() around the copy of the layer). What runs at a steady rate never
// does: the republisher and the saver get their data under small locks of their own.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/SetMap.h>
#include <ros/ros.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "pf_localization/ros/diagnostics/limited_warn.h"
#include "pf_localization/ros/diagnostics/update_timing.h"
#include "pf_localization/ros/input/time_jump_handler.h"
#include "pf_localization/ros/localizer/scan_localizer.h"
#include "pf_localization/ros/output/estimate_publisher.h"
#include "pf_localization/ros/output/map_changes_saver.h"
#include "pf_localization/ros/output/map_to_odom_republisher.h"
#include "pf_localization/ros/output/pose_saver.h"
#include "pf_localization/ros/params/reconfigure_server.h"
#include "pf_localization/ros/params/saved_pose.h"
#include "pf_localization/ros/scheduling/latest_scan_slot.h"
#include "pf_localization/ros/scheduling/update_placement.h"
#include "pf_localization/ros/scheduling/update_scheduler.h"
#include "pf_localization/ros/scheduling/update_time_governor.h"

namespace pf_ros {

class LiveLocalizer {
 public:
  /// `saved`: config.initial_pose was saved by an earlier run (isSavedPose()).
  /// `tf`, `republisher` and `warn` must outlive it; the topics are
  /// advertised on `nh`; `write_pose` saves the pose (saver()). Logs the
  /// initial pose it will start from.
  LiveLocalizer(const LocalizerConfig& config, std::optional<SavedPoseMap> saved,
                tf2_ros::Buffer* tf, MapToOdomRepublisher* republisher, LimitedWarn* warn,
                ros::NodeHandle& nh, PoseSaver::Write write_pose = {});

  /// A new map (map topic or set_map). False when it was refused (logged).
  /// Unlike the other methods, called without the filter's lock: the map is
  /// built without it, while updates and map -> odom go on from the current
  /// map, and `scheduler` lends it only to read what building needs and to
  /// swap the map in (prepared_map.h).
  bool installMap(const nav_msgs::OccupancyGrid& map, UpdateScheduler& scheduler);
  /// installMap's part without the filter's lock: `map` checked and built
  /// for the filter (ready.error says why it was refused), with the checksum
  /// a saver or a saved pose will check.
  struct BuiltMap {
    ScanLocalizer::ReadyMap ready;
    std::string signature;
    bool kept = false;  // a floor's map kept from an earlier visit, its change layer with it
  };
  BuiltMap buildMap(const nav_msgs::OccupancyGrid& map, UpdateScheduler& scheduler) const;
  /// A building's floor (floors.h), with the filter's lock held and in one
  /// hold of it, so that no update weighs the old floor's particles on the
  /// new map and map -> odom goes from one floor's to the other's: `built`
  /// (none: the floor stays) replaces the map, which goes to `*replaced`
  /// with what its change layer learned; then the filter starts at `pose`
  /// (moved on by the odometry since its stamp) or, without one, globally
  /// (a first map without a pose: as installMap's first map). `floor` names
  /// the floor on pf_status. The change layer of the floor left is copied
  /// for its file, and a floor's map built afresh (not `kept`) gets the
  /// layer its file holds (map_changes_saver.h). False when refused
  /// (logged): a refused pose leaves global localization on the new floor.
  bool changeFloor(std::optional<BuiltMap> built, const std::string& floor,
                   const std::optional<geometry_msgs::PoseWithCovarianceStamped>& pose,
                   std::optional<pf::PreparedMap>* replaced);
  /// Whether a map was installed. Changed only by installMap(), which pf_node
  /// calls from its main spinner; read there without the mutex.
  bool haveMap() const { return have_map_; }

  /// pf_node's map sources, initial poses and global_localization, on its
  /// main spinner without the filter's lock, as installMap(). With a
  /// building's floors (floors.h, which calls useFloors() while it lives:
  /// `search` starts its search of every floor) the maps are the floors':
  /// the map topic is ignored and set_map refused. A map on the topic is
  /// ignored too after the first with first_map_only (both said at most
  /// every 5 s).
  void useFloors(std::function<bool()> search) { floor_search_ = std::move(search); }
  void mapFromTopic(const nav_msgs::OccupancyGrid& map, const std::string& topic,
                    UpdateScheduler& scheduler);
  /// An initial pose (initialpose, set_map's) in any frame tf knows, moved
  /// into the global frame first (initialPoseInFrame). False when refused (warned).
  bool applyInitialPose(const geometry_msgs::PoseWithCovarianceStamped& pose,
                        UpdateScheduler& scheduler);
  /// amcl's set_map: a new map and the pose on it in one call (a robot moved
  /// to another floor), the pose the robot's when asked (a zero stamp: now;
  /// the odometry moves it on while the map builds). The map is installed
  /// even with first_map_only, which guards the map topic only.
  bool setMap(nav_msgs::SetMap::Request& request, UpdateScheduler& scheduler);
  /// With floors, on every floor, and meanwhile on the current one.
  bool globalLocalization(UpdateScheduler& scheduler);
  /// The floor the configured initial pose was saved on by an earlier run
  /// (saved_pose.h), until the first map checks it: empty when it is not a
  /// saved one or names no floor. Floors starts on it when it has it.
  std::string savedPoseFloor() const { return saved_pose_ ? saved_pose_->floor : ""; }

  /// For a search of every floor (floors.h), with the filter's lock held:
  /// the filter's live parameters, every update's odometry and scans
  /// (ScanLocalizer::observeUpdates), and the floor pf_status names.
  const pf::ParticleFilterParams& filterParams() const { return localizer_.filter().params(); }
  void observeUpdates(ScanLocalizer::UpdateObserver observer) {
    localizer_.observeUpdates(std::move(observer));
  }
  void showFloor(const std::string& floor, bool searching) { output_.setFloor(floor, searching); }
  const std::string& globalFrame() const { return config_.global_frame; }

  /// Re-initialises at `pose`, in the global frame. False when refused (warned).
  bool setInitialPose(const geometry_msgs::PoseWithCovarianceStamped& pose);
  bool startGlobalLocalization();
  void requestNoMotionUpdate() { localizer_.filter().requestNoMotionUpdate(); }

  /// The live parameters from ReconfigureServer: the filter's at its next
  /// update, the republisher's and max_update_time now. Empty, or the error.
  std::string reconfigure(const LocalizerConfig& next);

  /// Whether the next update may run on roscpp's poll thread
  /// (UpdatePlacement: the recent updates of this many particles were short).
  bool nextUpdateOnPollThread() const {
    return placement_.onPollThread(localizer_.filter().particles().size());
  }

  /// One scan, on the filter thread or the poll thread: the update and
  /// everything after it.
  /// `slot` (its scans dropped) and `reconfigure` (its generation): for the
  /// diagnostics, as they are after the update.
  void processScan(const PendingScan& pending, const LatestScanSlot& slot,
                   const ReconfigureServer& reconfigure);

  /// A scan tf dropped for `reason`: a sign of time jumping back (then
  /// everything starts over), or a rate-limited warning naming the
  /// transforms the scan needs.
  void scanDropped(const std_msgs::Header& header,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  /// The clock at a timed map -> odom: under simulated time it may show
  /// time jumping back, often before any scan of the new timeline gets
  /// through tf.
  void clockTick(const ros::Time& now);

  /// The pose to save and its schedule (pose_saver.h): may be used without
  /// the filter's lock. Its saves write the layer of the map's changes too.
  PoseSaver& saver() { return saver_; }
  /// At shutdown, on the main spinner without the filter's lock: the pose
  /// saved (when a master answers) and the layer of the map's changes as it
  /// is now (`scheduler` lends the lock to copy it). Nothing when saving is off.
  void saveAtShutdown(UpdateScheduler& scheduler);

  /// The clear_map_changes service: the layer of the map's changes emptied,
  /// pf_map_changes published so, the file overwritten at the next save.
  /// False without a map.
  bool clearMapChanges();

 private:
  void logInitialPose() const;
  // installMap's part with the filter's lock held: `built`, from a map
  // stamped `stamp` (floor `floor`'s with a building's floors, else empty),
  // replaces the filter's map (which goes to `replaced`, if any);
  // `announce`: map -> odom and the estimate go out now.
  bool install(BuiltMap built, const ros::Time& stamp, const std::string& floor = "",
               std::optional<pf::PreparedMap>* replaced = nullptr, bool announce = true);
  void checkSavedPose(const std::string& map_signature, const std::string& floor);
  // A new map of signature `signature` (floor `floor`'s, or none) for the
  // layer's saver; when `restore`, the layer saved on it restored and published.
  void mapChangesOnNewMap(const std::string& signature, const std::string& floor, bool restore,
                          const ros::Time& stamp);
  // The layer's copy written now, if any (a warning if it cannot be).
  void writeMapChanges();
  void restartAfterJump(double back_s);
  void applyParticleCap(std::size_t cap);
  void filterChanged(const ros::Time& scan_stamp);

  const LocalizerConfig config_;  // as read at start-up: the live values are localizer_'s
  tf2_ros::Buffer* tf_;
  MapToOdomRepublisher* republisher_;
  LimitedWarn* warn_;
  ScanLocalizer localizer_;
  UpdateTimeGovernor governor_;
  UpdateTiming timing_;
  UpdatePlacement placement_;
  EstimatePublisher output_;
  TimeJumpHandler jumps_;
  MapChangesSaver changes_saver_;
  PoseSaver saver_;
  bool have_map_ = false;
  std::optional<SavedPoseMap> saved_pose_;  // until the first map checks it
  bool saved_pose_ignored_ = false;         // it was, and global localization started
  bool pose_before_map_ = false;            // an initial pose replaced it before any map
  std::optional<pf::Pose2> last_odom_;      // odom -> base at the latest scan used
  std::function<bool()> floor_search_;      // while a building's floors own the maps
};

}  // namespace pf_ros
