// What each beam of a scan says about the map, seen from one pose.
//
// The likelihood field scores a beam by where it ends, never by the way it
// went: a beam that stops in the open (a cabinet, a pallet, a person the map
// lacks) and one that passes through a mapped wall and ends on the wall
// behind it both just "fit worse". Along the ray they differ, and that is
// what tells a map out of date from a wrong pose: at the right pose an
// object the map lacks stops beams short of the map's walls, an object that
// is gone lets beams through, and the rest of the scan ends on the map; at a
// wrong pose beams run through walls and off the map everywhere. This is the
// free-space reasoning of change detection on occupancy maps (Meyer-Delius,
// Hess, Grisetti & Burgard, "Temporary maps for robust localization in
// semi-static environments", IROS 2010; Tipaldi, Meyer-Delius & Burgard,
// "Lifelong localization in changing environments", IJRR 2013), and the
// beam model's short and max readings (Thrun et al., "Probabilistic
// Robotics", 2005, sec. 6.3) judged once per beam at one pose instead of per
// particle. The ray is cast on the occupancy grid by sphere tracing on the
// likelihood field's own distances, as the beam model's ray caster does on
// its table (distance_field_ray_caster.h), on the map as the change layer has
// learned it (map_change_layer.h; the temporary map of Meyer-Delius et al.
// used for the judging): rays pass the obstacles it has seen gone, and a
// beam that ends on an object it has seen added sees a change. See
// docs/design.md, "A map out of date is not a wrong pose".
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

enum class BeamEvidence : std::uint8_t {
  kNoReading,   // the beam has no range
  kOnMap,       // ends on a mapped obstacle, the way there clear
  kShortOfMap,  // ends well before the map's next obstacle: something the map lacks
  // Passes a mapped obstacle well before its end (it is gone, or the pose is
  // wrong), and ends on another one; near one, but on an object learned
  // added (counted as ending on the map, but a change); or in the open.
  kThroughOntoMap,
  kThroughOntoAdded,
  kThroughIntoOpen,
  kOffMap,  // ends outside the map
};

/// How many beams of a scan said what.
struct EvidenceCounts {
  std::size_t on_map = 0;
  std::size_t short_of_map = 0;
  std::size_t through_onto_map = 0;
  std::size_t through_into_open = 0;
  std::size_t off_map = 0;

  std::size_t beams() const {
    return on_map + short_of_map + through_onto_map + through_into_open + off_map;
  }
  /// Beams that end on a mapped obstacle, whatever they passed.
  std::size_t endingOnMap() const { return on_map + through_onto_map; }
  /// Beams the map contradicts at this pose: through a mapped obstacle into
  /// the open, or off the map; and, at kThroughOntoMapWeight, through a
  /// mapped obstacle onto another (a removed object, a thin obstacle's
  /// corner, a blurred wall: common on a real map at the right pose).
  double contradicting() const {
    return static_cast<double>(through_into_open + off_map) +
           kThroughOntoMapWeight * static_cast<double>(through_onto_map);
  }
  /// A quarter: a storage room whose two shelves are gone sends half its
  /// beams through them onto the walls behind; at a wrong pose the beams
  /// that run into the open or off the map are what tell.
  static constexpr double kThroughOntoMapWeight = 0.25;
  /// Beams that pass a mapped obstacle, wherever they end.
  std::size_t throughMap() const { return through_onto_map + through_into_open; }
  EvidenceCounts& operator+=(const EvidenceCounts& o);
};

class MapEvidence {
 public:
  /// m: a beam that passes a mapped obstacle and ends this close to another
  /// ends on the map (the likelihood field's hit distance, about).
  static constexpr double kOnMapDistance = 0.3;
  /// m: a mapped obstacle this close before a beam's end is the one it ends
  /// on, entered early by a centimetre of pose error or at a grazing angle.
  static constexpr double kThroughMargin = 0.3;
  /// m: a beam the map would let run this much further than it did stopped
  /// on something the map lacks (a closed door, a cabinet 0.35 m deep in
  /// front of a wall), unless it ends within kBesideObstacle of a mapped one
  /// (the edge of a table the ray only grazes).
  static constexpr double kShortMargin = 0.25;
  static constexpr double kBesideObstacle = 0.1;

  /// Casts rays on `field`'s grid, through its distances: nothing per cell
  /// of its own.
  explicit MapEvidence(const DistanceField& field);

  const DistanceField& field() const { return *field_; }

  /// Rays pass the mapped obstacle at the grid's cell index `cell` when
  /// `gone` (learned gone: MapChangeLayer), and stop there again when not.
  void setGone(std::size_t cell, bool gone);
  /// A beam that ends in the grid's cell `cell` ends on an obstacle the map
  /// lacks when `added` (learned: MapChangeLayer).
  void setAdded(std::size_t cell, bool added);

  /// The evidence of one beam from (sx, sy) along `angle` (world frame) that
  /// measured `range`.
  BeamEvidence judge(double sx, double sy, double angle, double range) const;

  /// Beams judged per scan at most: a scan of more beams is judged every
  /// n / kJudgedBeams beams, and each judged beam's verdict is its
  /// neighbours' up to the next: 4 degrees of a 360-beam scan, a few
  /// centimetres at the ranges where changes matter.
  static constexpr std::size_t kJudgedBeams = 90;
  /// m: a beam longer than this is taken as ending on the map. Far beams cost
  /// the most to cast (the CARMEN logs' 80 m) and say the least about the
  /// cabinets, doors and pallets a map misses; the Neato sees 5 m.
  static constexpr double kMaxJudgedRange = 10.0;

  /// The beams of `scan` placed from the robot pose `robot`, into `out` (one
  /// per range, kNoReading for a beam without a reading); the counts of the
  /// beams judged.
  EvidenceCounts judge(const LaserScan& scan, const Pose2& robot,
                       std::vector<BeamEvidence>* out) const;
  /// The counts of prepared scans (end points in the robot frame) placed
  /// from `robot`.
  EvidenceCounts count(const std::vector<PreparedScan>& scans, const Pose2& robot) const;

 private:
  // Whether (x, y) lies on or beside a cell learned added.
  bool endsOnAdded(double x, double y) const;
  // judge() along the unit vector (ux, uy).
  BeamEvidence judgeRay(double sx, double sy, double ux, double uy, double range) const;
  // The range from (cx, cy) along (dx, dy), both in cells of the grid's frame,
  // to the first occupied cell not gone, or max_range when there is none
  // within it on the map: sphereTrace (distance_field_ray_caster.h), each
  // cell's jump worked out from the field's distance as the ray reaches it
  // rather than read from a table of the map's size.
  double cast(double cx, double cy, double dx, double dy, double max_range) const;

  const DistanceField* field_;
  GridFrame frame_;  // to cast in cells
  float cells_per_metre_;
  // Cells (row-major indices) learned gone (setGone) and added (setAdded):
  // a few hundred where a map of millions of cells is out of date.
  std::unordered_set<std::size_t> gone_, added_;
};

}  // namespace pf
