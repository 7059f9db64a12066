// Test support: whether a map's free space is closed, for the tests of the
// simulator's maps.
#pragma once

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf::test {

/// Free cells reachable from (x, y) through 4-connected free cells, 0 when
/// (x, y) is not free, or -1 when one of them touches an unknown cell or the
/// edge of the map: a ray crosses cells 4-connectedly, so a leak like that
/// would let it out.
int closedRegionSize(const OccupancyGrid& g, double x, double y);

}  // namespace pf::test
