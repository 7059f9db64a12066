// Test support: an occupancy grid drawn as text, so that a test's world can be
// read at a glance.
#pragma once

#include <string>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf::test {

/// A grid drawn row by row, top row first (as it reads on the page, so the
/// last string is the grid's row 0, at the origin): '#' occupied (100), '.'
/// free (0), '?' unknown (-1). Throws std::invalid_argument for no rows,
/// rows of different lengths or any other character.
///   gridFromRows({"#####",
///                 "#...#",
///                 "#####"}, 0.1)    // 0.5 m x 0.3 m, walls around
OccupancyGrid gridFromRows(const std::vector<std::string>& rows, double resolution,
                           const Pose2& origin = {});

}  // namespace pf::test
