#include "pf_localization/core/map/distance_field_ray_caster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pf_localization/core/util/random.h"
#include "pf_localization/sim/ray_caster.h"
#include "support/rooms.h"

namespace pf {
namespace {

using test::wallGrid;

// The reference: the simulator's exact cell-by-cell traversal (Amanatides &
// Woo), a different algorithm from sphere tracing; max_range when it finds
// nothing.
double exact(const sim::RayCaster& reference, double x, double y, double angle, double max_range) {
  const double r = reference.cast(x, y, angle, max_range);
  return std::isfinite(r) ? r : max_range;
}

TEST(DistanceFieldRayCaster, RangesOnALiteralWall) {
  // 10 x 5 cells of 0.1 m; column 8 (x in [0.8, 0.9)) occupied.
  const DistanceFieldRayCaster caster(wallGrid(8));
  // Straight at the wall from x = 0.25: it is entered at x = 0.8.
  EXPECT_NEAR(0.55, caster.cast(0.25, 0.25, 0.0, 4.0), 1e-6);
  // At 30 deg from (0.35, 0.05): x = 0.8 after 0.45 / cos 30 = 0.519615 m,
  // at y = 0.31, still on the map.
  EXPECT_NEAR(0.45 / std::cos(M_PI / 6), caster.cast(0.35, 0.05, M_PI / 6, 4.0), 1e-6);
  // Away from the wall the ray leaves the map: max_range.
  EXPECT_EQ(4.0, caster.cast(0.25, 0.25, M_PI, 4.0));
  EXPECT_EQ(4.0, caster.cast(0.25, 0.25, M_PI / 2, 4.0));
  // A wall beyond max_range is not seen.
  EXPECT_EQ(0.5, caster.cast(0.25, 0.25, 0.0, 0.5));
  // Starting inside the wall: 0.
  EXPECT_EQ(0.0, caster.cast(0.85, 0.25, 0.0, 4.0));
}

TEST(DistanceFieldRayCaster, UnknownCellsAreTransparentAndAMapWithoutObstaclesIsOpen) {
  std::vector<int8_t> data(50, -1);  // all unknown
  const DistanceFieldRayCaster unknown(OccupancyGrid(10, 5, 0.1, {}, data));
  EXPECT_EQ(3.0, unknown.cast(0.25, 0.25, 0.0, 3.0));
  data.assign(50, 0);
  const DistanceFieldRayCaster empty(OccupancyGrid(10, 5, 0.1, {}, data));
  EXPECT_EQ(3.0, empty.cast(0.25, 0.25, 0.3, 3.0));
}

TEST(DistanceFieldRayCaster, AgreesWithTheExactTraversalOnARotatedMapWithPillars) {
  // 60 x 50 cells of 0.05 m, border walls and 2 x 2 pillars every 10 cells,
  // origin rotated: sphere tracing must skip space without skipping a corner.
  std::vector<int8_t> data(60 * 50, 0);
  for (int y = 0; y < 50; ++y) {
    for (int x = 0; x < 60; ++x) {
      const bool wall = x == 0 || y == 0 || x == 59 || y == 49;
      if (wall || (x % 10 < 2 && y % 10 < 2 && x > 3 && y > 3)) data[y * 60 + x] = 100;
    }
  }
  const OccupancyGrid grid(60, 50, 0.05, {-1.0, 0.5, 0.3}, data);
  const DistanceFieldRayCaster caster(grid);
  const sim::RayCaster reference(grid);
  Random random(7);
  int compared = 0;
  for (int i = 0; i < 300; ++i) {
    double wx, wy;
    grid.cellToWorld(
        {2 + static_cast<int>(random.index(56)), 2 + static_cast<int>(random.index(46))}, &wx, &wy);
    if (grid.state(grid.worldToCell(wx, wy)) == CellState::kOccupied) continue;
    const double angle = random.uniform(-M_PI, M_PI);
    EXPECT_NEAR(exact(reference, wx, wy, angle, 5.0), caster.cast(wx, wy, angle, 5.0), 2e-4)
        << "from " << wx << ", " << wy << " at " << angle;
    ++compared;
  }
  EXPECT_GT(compared, 200);
}

}  // namespace
}  // namespace pf
