// The cells where the world no longer matches its map, learned over time
// from what the lidars saw.
//
// Each scan added from a pose the filter trusts is walked cell by cell
// along some of its beams (Amanatides & Woo's grid traversal, "A fast voxel
// traversal algorithm for ray tracing", Eurographics 1987): a beam that ends
// in a cell the map has free, clear of its obstacles, counts a hit there; a
// cell the beam crosses well before its end counts a pass, free or through
// a mapped obstacle; a beam that ends on a mapped obstacle counts an end on
// it. A cell is added (an obstacle the map lacks) when most beams that
// reached it stopped there, and removed (a mapped obstacle that is gone)
// when most beams that reached it went through: the counting of occupancy
// mapping (Moravec & Elfes, ICRA 1985) kept beside the map, as the temporary
// maps of Meyer-Delius et al. (IROS 2010) do, instead of merged into it.
// People are not walls: a person who stands a while is hit by the beams of
// several scans as much as a cupboard is, so a cell is added only on what a
// person does not give. The scans since its last hit did not see through
// it (a static surface stops the beams that reach it; where a person
// stood, the beams run through once they have left: the latest evidence
// wins, as in occupancy mapping with clamping, Hornung et al., "OctoMap",
// Autonomous Robots 2013): kClearScans in a row take out a cell hit from
// robot places at least kMinBaseline apart, kOnePlaceClearScans one hit
// from one place only (the robot turning where it stood, or back where it
// was: a cupboard seen from one spot, or someone standing by); and, when
// the robot saw its place empty from nearby before the first hit
// (kMovedInPasses: something moved in while it looked, the free-space
// violation of moving object detection), many scans hit it
// (kMovedInScans). What moves is the
// transient screening's (transient_beams.h) and the judging's, which masks
// beams that end short of the map. See docs/design.md, "A map out of date
// is not a wrong pose", and its "People are not walls".
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

class MapChangeLayer {
 public:
  enum class Cell : std::uint8_t {
    kUnseen,    // no beam reached it
    kAsMapped,  // seen, and as the map has it
    kAdded,     // occupied in the world, free on the map
    kRemoved,   // occupied on the map, free in the world
  };

  /// Beams walked per scan at most (every n / kRaysPerScan of a scan of n).
  static constexpr std::size_t kRaysPerScan = 180;
  /// m: a beam is walked this far at most; a longer one has no end here.
  static constexpr double kMaxRange = 10.0;
  /// m: the cells this close before a beam's end are not counted as passed
  /// (the end point's own error, a blurred wall). Not more: an object moved
  /// 0.2 m behind where the map has it is seen through up to its far side.
  static constexpr double kEndMargin = 0.15;
  /// m: an end point this close to a mapped obstacle ends on it, not short.
  static constexpr double kBesideObstacle = 0.1;
  /// Scans whose beams reached a cell before it can be called changed (a
  /// scan counts once per cell, however many of its beams reached it).
  static constexpr int kMinScans = 2;
  /// Share of those that must say it changed: stopped there (added) or went
  /// through (removed).
  static constexpr double kChangedShare = 0.5;
  /// m: a cell's hits came from robot places at least this far apart (the
  /// first hit's place and a later one): two scans added while the robot
  /// drove (kMinStep), not the scans added while it turned in place, where
  /// a cupboard and someone standing by look the same.
  static constexpr double kMinBaseline = 0.4;
  /// Scans in a row whose beams went through a cell, none ending there,
  /// since its last hit that take it out of the added cells (until it is hit
  /// again): where a person stood, the beams run through once they have
  /// left. Fewer are not enough: a beam grazing a surface's face passes the
  /// cells just before it (a pallet along an aisle, seen down the aisle).
  static constexpr int kClearScans = 3;
  /// The same for a cell hit from one place only (not kMinBaseline apart):
  /// two scans through it since its last hit; it is kept until then, a
  /// surface seen from one spot only (a planter, a cabinet seen across a
  /// room from where the robot turned). One is not enough either: a beam
  /// grazing its edge, seen again when the robot came back.
  static constexpr int kOnePlaceClearScans = 2;
  /// Beams through a free cell before its first hit that make what it hit
  /// something that moved in while the robot looked (a person walking up):
  /// such a cell is added only after kMovedInScans hits, a pallet put down
  /// for good, not a person who stopped a while.
  static constexpr int kMovedInPasses = 3;
  static constexpr int kMovedInScans = 8;
  /// m: only beams within this of the sensor count those passes: further,
  /// a beam grazes the side of what it later hits (a pallet seen down an
  /// aisle).
  static constexpr double kMovedInRange = 3.0;
  /// m: the robot's place at a hit is kept in units of this.
  static constexpr double kPlaceUnit = 0.1;

  /// An empty layer of `field`'s map.
  explicit MapChangeLayer(const DistanceField& field);

  /// m, rad: a scan is worth adding once the robot moved this far or turned
  /// this much since the last one added: a scan from the same place says
  /// again what the last one said, and each costs a walk of every beam.
  static constexpr double kMinStep = 0.4;
  static constexpr double kMinTurn = 0.5;

  /// Whether a scan from `robot` is worth adding (kMinStep, kMinTurn).
  bool wants(const Pose2& robot) const;
  /// Adds what `scans`, placed from the robot pose `robot`, saw.
  void add(const ScanGroup& scans, const Pose2& robot);
  /// Forgets everything seen.
  void clear();

  int width() const { return width_; }
  int height() const { return height_; }
  Cell cell(int x, int y) const { return classify(y * width_ + x); }

  struct Summary {
    std::size_t seen = 0, added = 0, removed = 0;
    // The evidence behind them: over the added cells, the scans whose beams
    // stopped there (hits); over the removed ones, the scans whose beams went
    // through the mapped obstacle (passes). Each cell has at least kMinScans.
    std::size_t added_scans = 0, removed_scans = 0;
    double changedShare() const {
      return seen == 0 ? 0.0 : static_cast<double>(added + removed) / static_cast<double>(seen);
    }
  };
  Summary summary() const { return summary_; }

  /// Every cell as a nav_msgs/OccupancyGrid value, row-major from the
  /// lower-left cell: -1 unseen, 0 seen as mapped, 100 added, 50 removed
  /// (each cell's state is kept up to date as scans are added, in two bits
  /// of its byte: a message costs a pass over the cells).
  std::vector<std::int8_t> occupancy() const;
  /// The same into `out` (resized): a message's storage used again, not
  /// allocated (and faulted in) once more, and no branch per cell.
  void occupancy(std::vector<std::int8_t>* out) const;
  static std::int8_t valueOf(Cell c);
  /// Every cell as an image's pixel (saveImage, map_loader.h), in the true
  /// change mask's convention (pf_simulator --change-mask): 0 added, 205
  /// removed, 254 seen as mapped; and 128 unseen.
  std::vector<std::uint8_t> pixels() const;
  /// Scans added so far.
  std::size_t scans() const { return scans_; }

  /// Whether the cell at row-major index i is a mapped obstacle seen gone;
  /// an obstacle the map lacks.
  bool removed(std::size_t i) const { return shown(i) == Cell::kRemoved; }
  bool added(std::size_t i) const { return shown(i) == Cell::kAdded; }
  /// The cells (row-major indices) that became added or removed, or stopped
  /// being, since the last call: what the judging of scans learns.
  std::vector<std::size_t> takeChangedCells();

  /// What the layer learned as bytes, to restore on the same map after a
  /// restart: the map's size, the scans added and the last one's pose, the
  /// state of each cell run-length coded (a building's millions of unseen
  /// cells are a few bytes; with the beams through it before its first hit)
  /// and the counts of the cells that have any (with the place of the first
  /// hit, whether one came from afar, whether it moved in and the clear
  /// scans since the last hit), as variable-length integers
  /// (map_change_file.h frames them in a file).
  std::string encode() const;
  /// The state encode() wrote, on a layer of a map of the same size: empty,
  /// or why the bytes were refused (another map's size, truncated, corrupt)
  /// and the layer left empty. Every restored added and removed cell is then
  /// listed by takeChangedCells().
  std::string decode(const std::string& bytes);

 private:
  // Scans, each counted once per cell and kind.
  struct Counts {
    std::uint16_t hits = 0;  // a beam ended here, the map free and clear around
    // A beam passed, the map free here, since the first hit (what passed
    // before says nothing of an object that came later).
    std::uint16_t free = 0;
    std::uint16_t passes = 0;  // a beam passed, the map occupied here
    std::uint16_t ends = 0;    // a beam ended on this mapped obstacle
    std::uint16_t scan = 0;    // the last scan that counted here (scans_, wrapping)
    std::uint8_t counted = 0;  // of that scan: a bit per kind already counted
    // Since the last hit: scans in a row whose beams passed (free), none hit.
    std::uint8_t clear = 0;
    // Whether a hit came from kMinBaseline or further from the first's place.
    std::uint8_t apart = 0;
    // Whether kMovedInPasses beams went through the cell before its first hit.
    std::uint8_t moved_in = 0;
    // The robot's place at the first hit, in kPlaceUnit of the map's frame.
    std::int16_t hit_x = 0, hit_y = 0;
  };
  enum Kind : std::uint8_t { kHit = 1, kFree = 2, kPass = 4, kEnd = 8 };
  // Each cell's byte: what the map has there (the low two bits), whether a
  // beam reached it, whether one ever ended there short of the map, and the
  // Cell it is shown as (two bits from kShownShift).
  enum MapCell : std::uint8_t { kMapFree, kMapBeside, kMapOccupied, kMapUnknown, kMapBits = 3 };
  // kPassedOne counts (to 3, in kPassedBits) the beams that went through a
  // cell the map has free before any ended there.
  enum Flag : std::uint8_t { kSeen = 4, kWasHit = 8, kPassedOne = 64, kPassedBits = 192 };
  static constexpr int kShownShift = 4;
  static constexpr std::uint8_t kShownBits = 3 << kShownShift;
  Cell shown(std::size_t i) const { return static_cast<Cell>(cells_[i] >> kShownShift & 3); }

  // Square tiles of kTileSize cells a side hold the counts, each made when a
  // beam first counts in it: a beam reaches kMaxRange at most, so a run
  // touches the tiles along its path, not a warehouse's millions of cells.
  static constexpr int kTileBits = 5;
  static constexpr int kTileSize = 1 << kTileBits;
  // Cell i's counts (its tile made if it was not); zeros in a tile not made.
  Counts& countsAt(std::size_t i);
  const Counts& countsAt(std::size_t i) const;
  // The index in tiles_ of cell i's tile, and of the cell in its tile.
  std::size_t tileOf(std::size_t i, std::size_t* in_tile) const;

  Cell classify(std::size_t i) const;
  // Counts `kind` in cell i, once per scan.
  void count(std::size_t i, Kind kind);
  // Marks cell i seen.
  void see(std::size_t i);
  // decode() without the clearing on error, and the check of what it read
  // that fills summary_ and changed_cells_.
  std::string restore(const std::string& bytes);
  std::string summarize();
  // Adds (`add`) or takes the evidence of a cell shown as `shown_as` with
  // counts `c` to or from summary_.
  void weigh(Cell shown_as, const Counts& c, bool add);
  // Shows cell i as `c` (occupancy()), and keeps summary_ and changed_cells_.
  void show(std::size_t i, Cell c);
  // One beam from (x, y) along (ux, uy), in cells of the grid's frame.
  void walk(double x, double y, double ux, double uy, double range);
  // The end point of a beam, in cells of the grid's frame.
  void end(double x, double y);

  int width_, height_;
  std::int16_t place_x_ = 0, place_y_ = 0;        // the robot's place in the scan being added
  GridFrame frame_;                               // to walk in cells
  std::vector<std::uint8_t> cells_;               // MapCell | Flag | shown Cell
  int tiles_x_;                                   // tiles per row
  std::vector<std::unique_ptr<Counts[]>> tiles_;  // row-major; null: no count yet
  Summary summary_;                               // of the cells shown
  std::vector<std::size_t> changed_cells_;        // takeChangedCells()
  std::size_t scans_ = 0;
  Pose2 last_;  // the robot pose of the last scan added
};

}  // namespace pf
