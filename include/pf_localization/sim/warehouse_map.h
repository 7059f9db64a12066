// The warehouse map: a 118 x 78 m hall of
// pallet racks, drawn by code like the building (building_map.h) so that it
// can be regenerated bit for bit (pf_make_map writes maps/warehouse.pgm and
// .yaml: 2400 x 1600 cells of 0.05 m, extent x -1..119, y -1..79).
//
//   y=77.7 +---------------------------------------------------+--------+
//          |                  north main aisle                 | office |
//   y=68.4 |   [==row 10==]   [==========]   [==========]      +-door---+ y=71
//          | w     aisle 10                                           e |
//          | e [==row 9===]   [==========]   [==========]             a |
//          | s      ...  11 identical double rows, the                s |
//          | t      10 twin aisles (3 m) between them                 t |
//          |   [==row 1===]   [==========]   [==========]               |
//          |       aisle 1                                              |
//   y=12.0 |   [==row 0===]   [==========]   [==========]               |
//          |     o(20,7)    o(40,7)    o(60,7)    o(80,7)    o(100,7)   |
//          |  staging area (pillars o)                                  |
//    y=0.3 +---u-u-u---u-u-----u-u-----u--------------------------------+
//         x=0.3  loading dock: 8 door recesses (u), irregular      x=117.7
//   the rows' segments: x 10.0-39.8, 44.0-73.8, 78.0-107.8; between
//   them cross aisles 1 and 2 (4.2 m); west and east main aisles ~10 m
//
// What a 2D lidar at ~0.2 m above the floor sees of a rack: its uprights,
// and nothing of its beams (the lowest beam level is above it) nor of the
// pallets on the floor positions, which come and go and are not on the map.
// A row is two racks 1.1 m deep back to back with a 0.2 m flue, 2.4 m in
// all; the lidar sees four lines of 0.1 m square uprights every 2.7 m along
// the row (at 0, 1.0, 1.3 and 2.3 m across it) and, in the flue, a wire
// mesh from the floor up (as fire code or anti-collapse mesh closes many
// flues), a continuous 0.1 m line: so an aisle's lidar sees its own two rack
// faces and the mesh behind each, never the next aisle.
//
// The twins: the ten aisles between the rows (kWarehouseAisles, numbered 1
// to 10 from the south) are identical cell for cell, and so is each row's
// stretch along any one segment; the rack block is also symmetric under a
// half turn about its centre (58.9, 40.2), so aisle a facing west looks like
// aisle 11 - a facing east. Inside an aisle the rack faces and their meshes
// hide everything else; the walls at the aisles' ends, seen down the aisles,
// are plain and tell the segments apart, not the aisles. What tells the
// aisles apart is the edge of the rack block, seen down a cross or main
// aisle: the staging area south of row 0 with its five pillars and the
// loading dock (door recesses at irregular spacing in the south wall), and
// the north main aisle with the office in the north-east corner. For a
// 25 m lidar in a cross aisle at aisle 4 or 7 the block's nearer edge is
// 20.1 m away; at aisles 5 and 6 both are beyond 25.5 m, so a robot there
// must drive 0.5-6 m towards one before it can know which aisle it is in.
//
// The pallets (warehousePallets) stand in the aisles and the staging area
// for the simulator's lidar; the map does not have them.
#pragma once

#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/sim/building_map.h"
#include "pf_localization/sim/scene_3d.h"

namespace pf::sim {

/// The map's extent, and the free space inside the 0.3 m outer walls.
inline constexpr Box kWarehouseExtent{-1.0, -1.0, 119.0, 79.0};
inline constexpr Box kWarehouseInterior{0.3, 0.3, 117.7, 77.7};

/// Rack rows 0..kWarehouseRows-1 along x; row k spans y from
/// warehouseRowY(k) to warehouseRowY(k) + kWarehouseRowDepth.
inline constexpr int kWarehouseRows = 11;
inline constexpr double kWarehouseRowDepth = 2.4;
inline constexpr double kWarehouseRowPitch = 5.4;  // so the aisles are 3.0 m
/// Each row is cut into segments by the cross aisles; a segment starts at
/// an upright's west face and has kWarehouseBays bays of kWarehouseBayPitch.
inline constexpr double kWarehouseSegmentX[] = {10.0, 44.0, 78.0};
inline constexpr int kWarehouseBays = 11;
inline constexpr double kWarehouseBayPitch = 2.7;
inline constexpr double kWarehouseUpright = 0.1;  // square, m
inline constexpr double kWarehouseSegmentLength =
    kWarehouseBays * kWarehouseBayPitch + kWarehouseUpright;
/// The twin aisles between the rows, numbered 1..kWarehouseAisles.
inline constexpr int kWarehouseAisles = kWarehouseRows - 1;

/// The south face of rack row k.
double warehouseRowY(int row);
/// Twin aisle a (1..10): between the rows' faces, from the first segment's
/// west end to the last one's east end.
Box warehouseAisle(int aisle);

/// The warehouse map (0.05 m cells).
OccupancyGrid makeWarehouseMap();

/// Loaded pallets (1.2 x 0.8 m, 1.2 m high) standing in the aisles, a cross
/// aisle and the staging area, in free space of the map but not on it.
std::vector<Box3> warehousePallets();

}  // namespace pf::sim
