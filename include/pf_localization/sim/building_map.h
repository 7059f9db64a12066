// The package's own maps, drawn procedurally so that they can be regenerated
// bit for bit (pf_make_map writes them to maps/).
//
// A map is drawn on a canvas that starts unknown: free boxes for rooms and
// corridors are carved out of occupied blocks, then doorways, furniture and
// pillars are added. Coordinates are map-frame metres on the 0.05 m grid, so
// every box edge falls on a cell boundary and no cell is half inside.
//
// The building (20 x 15 m, an L-shaped outline with unknown space around it):
//
//   y=15 +-----------+-----------+-------------+
//        | twin      | twin      | lab with    |      (unknown notch)
//        | room A    | room B    | 4 pillars   +---------+
//        |           |           |             | office  |
//        +--door-----+--door-----+---door------+--door---+ y=8.5
//        |            east-west corridor, 1.8 m wide     |
//        +--door-----+----wide opening---+--door---------+ y=6.5
//        | kitchen   | lobby: diagonal   | storage:      |
//        | island,   | wall, round column| shelves,      |
//        | wall stub |                   | locked closet |
//   y=0  +-----------+-------------------+---------------+
//       x=0                                             x=20
//
// The twin rooms are identical cell for cell, and the corridor offers long
// stretches that look alike, so a robot in one of them cannot tell where it
// is; the lab, the lobby and the storage room are each unlike anything else,
// which is what lets global localization converge once the robot sees them.
#pragma once

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/sim/map_canvas.h"

namespace pf::sim {

/// Interiors of the two identical rooms of the building.
inline constexpr Box kTwinRoomA{0.3, 8.65, 4.9, 14.7};
inline constexpr Box kTwinRoomB{5.05, 8.65, 9.65, 14.7};

/// The building map (0.05 m cells).
OccupancyGrid makeBuildingMap();

/// The building's upper floor (0.05 m cells): the same L-shaped outline, laid
/// out otherwise. The lift lobby at the east end is where the ground floor's
/// corridor ends (kLiftLobby: a robot there is in free space on both floors);
/// west of it, through a door, an open-plan office of desks and two columns;
/// north, two meeting rooms; beside the lobby, a server room and a
/// kitchenette. maps/building_floors.yaml names the two floors.
///
///   y=15 +-----------------+-----------------+
///        | meeting room 1  | meeting room 2  |
///        +--door-----------+--door-----------+----+ y=11.5
///        |  open-plan office: desks,         |kit.|
///        |  two columns, a partition         +----+ y=8.65
///        |                                 door lift|
///        |                                   +----+ y=6.5
///        |                                   |srv.|
///   y=0  +-----------------------------------+----+
///       x=0                                 17.45 20
OccupancyGrid makeUpperFloorMap();
/// The lift lobby's free space on the upper floor; on the ground floor the
/// corridor's east end.
inline constexpr Box kLiftLobby{17.6, 6.65, 19.7, 8.5};

/// A small asymmetric room, 6 x 4 m, with a cabinet, a column and a wall stub
/// (0.05 m cells), for fast tests.
OccupancyGrid makeSmallMap();

/// The corridor map: a straight corridor 2.2 m wide along x, 35.55 m long
/// between a room at its west end and a T-junction at its east end (42.5 m
/// in all); walls 0.3 m thick with unknown space behind them, as in a map
/// built by SLAM. From its west end to x = kCorridorFeaturelessFrom the walls
/// have doors at irregular spacing: four open into small rooms, five closed
/// ones and an alcove are recesses in the walls, one closed door stands in a
/// frame, a radiator stands out 0.1 m; from there to the T-junction (16.2 m,
/// over three times a Neato's 5 m range) the two walls are plain and
/// parallel, so that a lidar there sees nothing that says how far along the
/// corridor it is.
///
///   y=8 +------+ +-N1-+    +-N2-+                                    +---+
///       | room | |    |    |    |                                    |   |
///       |      +-+-  -+-[]-+-  -+-[]--+------------------------------+   |
///       |        doors stretch        |  featureless stretch         | T |
///       |      +--[]-+-  -+--[]--+-  -+------------------------------+   |
///       |      |     | S1 |      | S2 |                              |   |
///   y=0 +------+     +----+      +----+                              +---+
///      x=0   4.45                   23.8                          40.0  42.5
///   ("-  -": an open door, "[]": a closed one in a recess)
inline constexpr Box kCorridorExtent{-0.2, -0.2, 42.7, 8.2};
/// The corridor's own free space, from the west room to the T-junction.
inline constexpr Box kCorridorInterior{4.45, 2.85, 40.0, 5.05};
/// Where the featureless stretch begins; it ends at kCorridorInterior.x1.
inline constexpr double kCorridorFeaturelessFrom = 23.8;

/// The corridor map (0.05 m cells), for sliding along a corridor whose walls
/// constrain the pose across it but not along it.
OccupancyGrid makeCorridorMap();

}  // namespace pf::sim
