#include "pf_localization/core/recovery/random_free_pose.h"

#include <cmath>
#include <vector>

namespace pf {

Pose2 randomFreePose(const OccupancyGrid& grid, Random* random) {
  const std::vector<int>& free = grid.freeCells();
  const int cell = free[random->index(free.size())];
  const CellIndex c{cell % grid.width(), cell / grid.width()};
  // Anywhere inside the cell, not only its centre.
  const Pose2 local{(c.x + random->uniform()) * grid.resolution(),
                    (c.y + random->uniform()) * grid.resolution(), random->uniform(-M_PI, M_PI)};
  return compose(grid.origin(), local);
}

}  // namespace pf
