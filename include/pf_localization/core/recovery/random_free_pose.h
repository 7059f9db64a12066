// A pose drawn uniformly over a map's free space: the particles of a global
// localization and the random guesses recovery injects (Thrun et al.,
// "Probabilistic Robotics", table 8.3).
#pragma once

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/util/pose2.h"
#include "pf_localization/core/util/random.h"

namespace pf {

/// A free cell of `grid` chosen uniformly, a point uniformly inside it and a
/// uniform yaw in [-pi, pi), in the map frame, drawn from `random` in that
/// order. Precondition: grid.freeCells() is not empty.
Pose2 randomFreePose(const OccupancyGrid& grid, Random* random);

}  // namespace pf
