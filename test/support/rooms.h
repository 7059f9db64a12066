// Test support: the walled rooms and the single wall the tests' worlds are
// made of.
#pragma once

#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf::test {

/// An axis-aligned box in the grid's frame, metres: a cell is filled when
/// its centre lies strictly inside.
struct Box {
  double x0, y0, x1, y1;
};

/// A room of width x height metres (rounded to whole cells) with one-cell
/// walls on its border and the given boxes filled; everything else free.
OccupancyGrid room(double width, double height, double resolution,
                   const std::vector<Box>& boxes = {}, const Pose2& origin = {});

/// 10 m x 10 m in 0.05 m cells, the simulator tests' floor: walled like
/// room() (the walls' inner faces at 0.05 and 9.95 m), or free everywhere
/// (`walls` false) for rays that find nothing.
OccupancyGrid tenMetreRoom(bool walls = true);

/// A 4 m x 3 m room in 0.05 m cells with a box near its lower right
/// (x 2.5-3.0, y 0.5-1.2) and a smaller one near its upper left (x 0.6-1.0,
/// y 2.0-2.4), so that no rotation or mirror image of it looks the same.
OccupancyGrid asymmetricRoom();

/// 10 x 5 cells of 0.1 m (1 m x 0.5 m), free but for the cells of column
/// `column`: a single wall, x in [column / 10, column / 10 + 0.1) in the
/// grid's frame, whose ranges and distances are easy to work out by hand.
OccupancyGrid wallGrid(int column, const Pose2& origin = {});

/// The change layer's tests' room: 6 m x 4 m in 0.05 m cells, the world with
/// a box the map lacks (kChangedRoomAdded), the map with a box the world no
/// longer has (kChangedRoomRemoved).
inline constexpr Box kChangedRoomAdded{4.0, 1.7, 4.6, 2.3};
inline constexpr Box kChangedRoomRemoved{1.2, 2.6, 1.8, 3.2};
OccupancyGrid changedRoomWorld();
OccupancyGrid changedRoomMap();
/// The robot's poses in it: round the room's middle, where it sees both boxes.
std::vector<Pose2> changedRoomTour();

}  // namespace pf::test
