// A world that differs from its map: the changes a building or a warehouse
// went through after it was mapped, for pf_simulator --changes.
//
// A changes file is plain text, one command a line; '#' starts a comment,
// blank lines are ignored. Lengths are metres in the map frame; a box is
// x0 y0 x1 y1 with x0 < x1 and y0 < y1. A cell belongs to a shape when its
// centre does (as MapCanvas draws the maps, building_map.h), so a box whose
// edges fall on cell boundaries takes exactly the cells it covers:
//
//   add x0 y0 x1 y1         an object the map lacks (a cabinet, boxes, a
//                           closed door): the box's cells become occupied
//   add_disc x y r          a round one (a bin, a column), radius r
//   remove x0 y0 x1 y1      the occupied cells in the box become free
//                           (furniture gone, a door opened in a wall)
//   move x0 y0 x1 y1 dx dy  the occupied cells in the box move by (dx, dy),
//                           rounded to whole cells (furniture, a pallet, a
//                           rack bay moved): where they were is free
//
// The commands apply in order, each to the world the ones before it left:
// starting from a copy of the map, so a later `move` or `remove` sees what an
// earlier `add` put there. Unknown and free cells are never freed or moved.
// Every box (and a moved box's destination) must lie on the map, and a
// `remove` or `move` must find an occupied cell: otherwise the file is wrong
// ("file:line: message", MapChangesError).
//
// What changed is then judged cell by cell between the map and the world
// (the true change mask): an object the map lacks where the world is
// occupied and the map is not, an object the map has that is gone where the
// map is occupied and the world is not, unchanged elsewhere. So a table
// moved by less than its size counts only the strips it left and entered.
#pragma once

#include <cstdint>
#include <istream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/sim/building_map.h"

namespace pf::sim {

/// A malformed changes file, or one that does not fit its map. what() is
/// "file:line: message" (or "file: message" when it cannot be opened).
class MapChangesError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One command of a changes file.
struct MapChange {
  enum class Kind { kAdd, kAddDisc, kRemove, kMove };
  Kind kind = Kind::kAdd;
  Box box{0.0, 0.0, 0.0, 0.0};  // add, remove, move; add_disc: the disc's bounds
  double dx = 0.0, dy = 0.0;    // move
  int line = 0;
};

struct MapChanges {
  std::string file;  // for error messages
  std::vector<MapChange> changes;
};

/// Parses a changes file; `file` only names it in errors. Throws
/// MapChangesError for an unknown command, a wrong argument count, a bad
/// number, an empty box, a non-positive radius or a move by nothing.
MapChanges parseMapChanges(std::istream& in, const std::string& file);

/// Reads and parses a changes file. Throws MapChangesError (also when the
/// file cannot be opened).
MapChanges loadMapChanges(const std::string& path);

/// What became of a cell of the map in the world.
enum class CellChange : uint8_t { kUnchanged, kAdded, kRemoved };

/// A map's world, and how it differs from the map.
struct ChangedWorld {
  OccupancyGrid world;           // the map's geometry, the changed cells
  std::vector<CellChange> mask;  // one per cell, in the grid's order
  int added = 0;                 // cells occupied in the world only
  int removed = 0;               // cells occupied on the map only
  int map_occupied = 0;          // the map's occupied cells

  /// (added + removed) / map_occupied; 0 for a map without occupied cells.
  double changedShare() const;
  /// The mask as a trinary grid on the map's geometry, for saveMap
  /// (map_loader.h): added 100, removed -1, unchanged 0, which saveMap writes
  /// as the pixels 0 (black), 205 (grey) and 254 (white).
  OccupancyGrid maskGrid() const;
};

/// The linear indices of `map`'s cells whose centres lie in `box` (world
/// frame, edges included), in increasing order.
std::vector<int> cellsInBox(const OccupancyGrid& map, const Box& box);

/// Applies `changes` to `map` and judges the result. Throws MapChangesError
/// ("file:line: message") for a box off the map or a `remove` or `move` that
/// finds no occupied cell.
ChangedWorld applyMapChanges(const OccupancyGrid& map, const MapChanges& changes);

}  // namespace pf::sim
