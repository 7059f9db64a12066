// The layer of the map's changes (pf_map_changes, map_change_layer.h) kept
// across a restart, beside the saved pose (pose_saver.h): written to a file
// (map_changes_file; empty: defaultMapChangesPath()) with the signature of
// the map it was learned on (mapSignature, saved_pose.h), as
// map_change_file.h frames it, whenever the pose is saved (every
// 1 / save_pose_rate s and at shutdown); read back on the first map of the
// next run and restored only when the signatures are equal. A file is
// written whole to a temporary beside it, then renamed over it, so that a
// crash mid-write leaves the last one.
//
// With a building's floors (floors.h) each floor has a file of its own
// beside that one (floorMapChangesPath): the layer of the floor in use is
// saved as above, that of a floor left once more as the ride leaves it (it
// does not change while its map is kept), and each floor's is restored when
// its map is built (at start, or on the first ride there), on the same
// signature only.
//
// Threads, as PoseSaver's: the filter's side copies the layer into the
// file's bytes (offer(), with the filter's lock held, at most once a period
// and only when the layer changed since), and the main spinner writes the
// latest copy (writePending()) under a small mutex of the saver's own, so
// that a write never waits for an update nor an update for the disk. A
// copy is a pass over the cells' bytes, eight unseen ones at a time: 5 ms on
// a map of 48 million cells seen in part (0.3 ms on 4 million).
#pragma once

#include <ros/time.h>

#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/map/map_change_layer.h"

namespace pf_ros {

/// $ROS_HOME (else ~/.ros) / NODE.map_changes, NODE the node's name without
/// its leading '/' and with the others as '_' ("/robot1/pf_node":
/// robot1_pf_node.map_changes).
std::string defaultMapChangesPath(const std::string& node_name);

/// Floor `floor`'s file beside `path`: the floor's name, its bytes other
/// than letters, digits, '-' and '_' as %XX, before the extension
/// ("/r/pf_node.map_changes", "upper": /r/pf_node.upper.map_changes).
std::string floorMapChangesPath(const std::string& path, const std::string& floor);

/// What became of the file on the first map, for the log.
struct MapChangesRestore {
  enum class Level { kInfo, kWarn };
  Level level = Level::kInfo;
  std::string message;
  bool restored = false;
};
/// Reads `path` and restores its layer into `filter`'s (which has the map
/// whose mapSignature is `signature`) when it was learned on that map. A
/// file missing leaves the layer empty (INFO); another map's (both
/// signatures given), one that cannot be read or is refused
/// (readMapChangesFile, MapChangeLayer::decode) too, with a WARN.
MapChangesRestore restoreMapChanges(const std::string& path, const std::string& signature,
                                    pf::ParticleFilter* filter);

/// `bytes` written to `path` through a temporary beside it, renamed over it
/// (its folder made when missing). Empty, or why not.
std::string writeFileAtomically(const std::string& path, const std::string& bytes);

class MapChangesSaver {
 public:
  /// `rate`: save_pose_rate (<= 0: nothing is ever copied or written).
  MapChangesSaver(std::string path, double rate);

  bool enabled() const { return rate_ > 0.0; }
  /// The file given (a floor's: floorMapChangesPath()).
  const std::string& path() const { return path_; }

  /// Filter side. A new map, of signature `signature`: its layer is
  /// written, to `path` (empty: path()), from its first change on (the file
  /// keeps what it holds until then); `saved_scans`: the scans of the layer
  /// the file already holds (restored from it), not copied again. A copy of
  /// the map before not written yet still goes to its own file.
  void setMap(const std::string& signature, std::size_t saved_scans = 0,
              const std::string& path = "");
  /// The layer changed otherwise than by learning (cleared, restored).
  void changed() { dirty_ = true; }
  /// After the filter changed: `layer` copied when it changed since the last
  /// copy and a period has passed since (`now`), or at once when `now_anyway`.
  void offer(const pf::MapChangeLayer* layer, const ros::WallTime& now, bool now_anyway = false);

  /// Main spinner: the latest copy of each file written, when it was not
  /// yet. Empty, or why one could not be (its copy is kept for the next try).
  std::string writePending();

 private:
  const std::string path_;
  const double rate_;
  // The filter's side (its lock).
  std::string signature_;
  std::string current_path_;      // the file of the map in use
  std::size_t copied_scans_ = 0;  // the layer's scans at the last copy
  bool dirty_ = false;
  ros::WallTime last_copy_;
  // Shared with the main spinner.
  std::mutex mutex_;
  std::map<std::string, std::string> pending_;  // bytes not written yet, by file
};

}  // namespace pf_ros
