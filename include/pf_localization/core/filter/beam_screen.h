// The first stage of an update: each beam of a scan screened once, before
// anything is weighed, and what the screening saw learned into the layer of
// the map's changes after the update.
//
// A beam that sees something that moved in while the robot stood still
// (transient_beams.h) or a change of the map (map_change_mask.h, judged
// with MapEvidence on the map as the layer has learned it) says nothing
// about where the robot is: the screening masks it like a beam without a
// reading. The later stages see one ScreenedScan: the gate, the look-alikes
// and the verdict's fit take every beam that did not see something move
// in; the weighing and the scan fit take only the beams the map explains.
// After an update whose scan agreed with the map at a pose the filter
// trusts, the scan's beams are walked into MapChangeLayer (the counting of
// occupancy mapping beside the map), and what it learned is shared with the
// judging. See docs/design.md, "A map out of date is not a wrong pose", and
// docs/how-it-works/sensor.md.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/map/map_change_layer.h"
#include "pf_localization/core/map/map_change_mask.h"
#include "pf_localization/core/map/map_evidence.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/sensor/transient_beams.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

/// Where the filter believes the robot is at a scan's odometry: the last
/// estimate moved by the odometry since (or the pose a cloud was just drawn
/// around), and whether it is known well enough to judge beams from.
struct TrackedPose {
  std::optional<Pose2> pose;  // none without a map or before the first update of a global cloud
  bool judges = false;        // one place, told apart, not lost, a short step since
};

/// What the screening did, for the update's report.
struct ScreenReport {
  int beams_masked = 0;  // seeing something that moved in while the robot stood (transient_beams.h)
  int beams_changed = 0;  // seeing a change of the map where the tracked pose fits the rest
  // What the beams said of the map at the tracked pose (map_evidence.h):
  // all zero when they were not judged (no pose to judge from).
  EvidenceCounts map_evidence;
  // Whether the scan agreed with the map there (the beams seeing changes
  // were masked), and the share of its beams that saw a change then.
  bool map_agrees = false;
  double map_changed_share = 0.0;
};

/// One scan as the stages after the screening see it. The groups view the
/// measured scans or the screen's copies: valid until the next screen().
struct ScreenedScan {
  ScanGroup measured;  // as the sensors gave it: what the layer learns from
  ScanGroup steady;    // without the beams that saw something move in
  ScanGroup fitting;   // nor those that saw a change of the map: what is weighed and fitted
  ScreenReport report;
};

/// The beams of a ScreenedScan as the sensor model prepares them: the
/// steady ones (the gate prepares them), and the fitting ones, prepared
/// anew only when the screening masked a change of the map.
class PreparedBeams {
 public:
  PreparedBeams(const SensorModel& model, const ScreenedScan& scan,
                std::vector<PreparedScan> steady);
  const std::vector<PreparedScan>& steady() const { return steady_; }
  const std::vector<PreparedScan>& fitting() const { return fitting_ ? *fitting_ : steady_; }

 private:
  std::vector<PreparedScan> steady_;
  std::optional<std::vector<PreparedScan>> fitting_;
};

class BeamScreen {
 public:
  /// What the screening builds from a map: the rays the judging casts on
  /// it, and the layer of its changes, empty.
  struct MapParts {
    MapEvidence evidence;
    MapChangeLayer layer;
  };
  static MapParts prepare(const DistanceField& field);
  /// A new map: the judging casts rays on it, and the layer of its changes
  /// starts empty (`parts`, prepared from its field).
  void setMap(MapParts parts);
  /// Takes the map's parts out, with what the layer learned
  /// (ParticleFilter::releaseMap); setMap(parts) later goes on from them.
  /// None are left. Precondition: a map was set.
  MapParts releaseMap();
  /// The same map under a new likelihood field (new sensor parameters): the
  /// judging casts on it, with what the layer learned.
  void setField(const DistanceField& field);

  /// Screens `measured`, taken at odometry `odom`, from `tracked`.
  ScreenedScan screen(const Pose2& odom, const ScanGroup& measured, const TrackedPose& tracked);

  /// After an update: adds `measured` to the layer, placed at `estimate`,
  /// when its scan agreed with the map, the verdict is not lost (`lost`) and
  /// the robot moved enough since the last scan added
  /// (MapChangeLayer::wants); the judging then takes what changed.
  void learn(const ScanGroup& measured, const Pose2& estimate, bool lost);

  /// The map's rays as the layer has them (none without a map).
  const MapEvidence* evidence() const { return evidence_ ? &*evidence_ : nullptr; }
  /// The layer of the map's changes (none without a map).
  const MapChangeLayer* layer() const { return layer_ ? &*layer_ : nullptr; }
  /// The layer restored from `state` (MapChangeLayer::decode()), the judging
  /// told all it holds: empty, or why not (then the layer is empty).
  std::string restoreLayer(const std::string& state);
  /// The layer emptied, the judging told.
  void clearLayer();

 private:
  // The scans with the beams that see something that moved in masked, from
  // `robot` (none: nothing is on the map).
  ScanGroup maskTransients(const Pose2& odom, const ScanGroup& measured,
                           const std::optional<Pose2>& robot);
  // Tells the judging the layer's added and removed cells: those that
  // changed, or (`all`) every one, for a new MapEvidence.
  void shareMapChanges(bool all);

  TransientBeams transients_;
  std::vector<LaserScan> steady_;  // the scans with the transient beams masked
  std::optional<MapEvidence> evidence_;
  MapChangeMask changes_;
  std::vector<LaserScan> fitting_;  // the scans with the beams seeing changes masked too
  std::optional<MapChangeLayer> layer_;
};

}  // namespace pf
