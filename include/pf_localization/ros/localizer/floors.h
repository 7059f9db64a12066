// A building's floors in pf_node (~floors_file, core/map/floors_file.h):
// which floor the robot is on (pf_floor, std_msgs/String, latched; and on
// pf_status), the change_floor service (srv/ChangeFloor.srv: a lift ride,
// with or without the pose on the new floor), and one prepared map per floor.
//
// A floor's map is loaded and prepared (pf::PreparedMap: the distance field,
// the likelihood tables, the screening's rays, the look-alike places) on the
// first visit, without the filter's lock, as a map on the map topic is
// (LiveLocalizer::installMap); the swap then happens in one hold of the lock
// (LiveLocalizer::changeFloor), so that map -> odom goes straight from one
// floor's to the other's. The map left behind is kept with what its change
// layer learned (ParticleFilter::releaseMap): a ride back installs it at
// once, and the layer goes on where it stopped. Built on first use rather
// than at start-up: a floor never visited costs neither the seconds nor the
// memory a prepared map takes (about ten bytes a cell: some 500 MB on a
// 200 x 600 m floor); a floor visited keeps its map for as long as the node
// runs (docs/how-it-works/map.md, "A building's floors").
//
// Global localization without a floor (pf_node's global_localization with a
// floors file) searches every floor (core/recovery/floor_search.h): each
// floor's map is built afresh for the search (the kept ones, and their change
// layers, are not touched by filters that may be on the wrong floor; the
// search holds every floor's map once more while it runs), the search's
// filters follow the filter's own scans (ScanLocalizer::observeUpdates), and
// a timer on the main spinner reads the verdict: when a floor is found, the
// robot moves there at the search's estimate, as change_floor would do, and
// pf_floor names it. Until then pf_floor is empty, and pf_status, whose floor
// is "unknown", is at least a warning led by "searching every floor: ": the
// filter itself runs global localization on the floor it was on meanwhile,
// and its verdict is about that floor's map.
//
// Threads: the services and the timer run on pf_node's main spinner, as
// set_map does; the floors' maps are touched only there and, for the swap,
// under the filter's lock; the search updates under the lock, on the
// filter's thread.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/MapMetaData.h>
#include <pf_localization/ChangeFloor.h>
#include <ros/ros.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/filter/prepared_map.h"
#include "pf_localization/core/map/floors_file.h"
#include "pf_localization/core/recovery/floor_search.h"
#include "pf_localization/ros/localizer/live_localizer.h"
#include "pf_localization/ros/scheduling/update_scheduler.h"

namespace pf_ros {

class Floors {
 public:
  /// A pose in the global frame, from one in any frame (pf_node: through
  /// tf); none when it cannot be moved there (warned).
  using ToGlobal = std::function<std::optional<geometry_msgs::PoseWithCovarianceStamped>(
      const geometry_msgs::PoseWithCovarianceStamped&)>;

  /// The floors file at `path`; none when it cannot be used (logged as
  /// fatal: pf_node does not start with a floors file it cannot read).
  static std::optional<pf::FloorsFile> read(const std::string& path);

  /// pf_node's floors: none without a floors file, else made and start()ed.
  static std::unique_ptr<Floors> create(std::optional<pf::FloorsFile> file, LiveLocalizer* live,
                                        UpdateScheduler* scheduler, ToGlobal to_global,
                                        ros::NodeHandle& nh);

  /// `live` and `scheduler` must outlive it. Advertises pf_floor and
  /// change_floor on `nh`, and has `live` leave the maps to it
  /// (LiveLocalizer::useFloors) while it lives; installs nothing yet (start()).
  Floors(pf::FloorsFile file, LiveLocalizer* live, UpdateScheduler* scheduler, ToGlobal to_global,
         ros::NodeHandle& nh);
  /// Ends a search still running: the filter's updates stop feeding it.
  ~Floors();
  Floors(const Floors&) = delete;
  Floors& operator=(const Floors&) = delete;

  /// Installs the initial floor's map, as the first map: the filter starts
  /// from the configured initial pose, or globally. A pose an earlier run
  /// saved on a floor (saved_pose.h) starts on that floor instead, when the
  /// file has it (otherwise the initial floor, where the pose is not used:
  /// one warning). False when its map cannot be loaded (logged; change_floor
  /// may still bring another floor's).
  bool start();

  /// Moves to floor `name`: at `pose` (any frame tf knows), or with global
  /// localization on it without one. On the current floor only the pose
  /// changes. Returns what was done, or why not (`ok` false), as the
  /// service answers.
  struct Outcome {
    bool ok = false;
    std::string message;
  };
  Outcome change(const std::string& name,
                 const std::optional<geometry_msgs::PoseWithCovarianceStamped>& pose);

  /// Starts a search of every floor (global_localization without a floor):
  /// false when a floor's map cannot be built (logged), and the filter's own
  /// global localization on the current floor then goes on alone.
  bool search();

  /// The current floor's name; empty before start() and during a search.
  std::string current() const;

 private:
  bool onChangeFloor(pf_localization::ChangeFloor::Request& req,
                     pf_localization::ChangeFloor::Response& res);
  // change()'s work, `pose` in the global frame already.
  Outcome moveTo(std::size_t index,
                 const std::optional<geometry_msgs::PoseWithCovarianceStamped>& pose);
  // Floor `index`'s map built for the filter (loaded and prepared now, or
  // kept from an earlier visit), or why it cannot be.
  std::optional<LiveLocalizer::BuiltMap> mapOf(std::size_t index, std::string* error);
  void publishFloor();
  // The search's verdict, every kSearchPeriod on the main spinner: a floor
  // found ends the search there.
  void checkSearch();
  // Ends the search, with the filter's lock held: the search's maps dropped.
  void stopSearch();

  // A floor's map while another is in use, with what its change layer learned.
  struct Kept {
    std::optional<pf::PreparedMap> map;
    nav_msgs::MapMetaData info;
    std::string signature;
  };

  const pf::FloorsFile file_;
  LiveLocalizer* live_;
  UpdateScheduler* scheduler_;
  ToGlobal to_global_;
  std::vector<Kept> kept_;              // one per floor
  std::optional<std::size_t> current_;  // the floor whose map the filter has
  ros::Publisher floor_pub_;
  ros::ServiceServer service_;
  std::unique_ptr<pf::FloorSearch> search_;  // while a search of every floor runs
  ros::Time search_stamp_;                   // of the last update the search followed
  std::string search_reason_;                // its last verdict's, as logged
  ros::WallTimer search_timer_;
};

}  // namespace pf_ros
