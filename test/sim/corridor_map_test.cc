// The corridor map (makeCorridorMap) has what bags/corridor.bag relies on: a
// straight corridor, a doors stretch with irregular features, a featureless
// stretch longer than twice the Neato's range where every scan looks the
// same, and two different ends.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "pf_localization/sim/building_map.h"
#include "pf_localization/sim/ray_caster.h"
#include "support/closed_region.h"

namespace pf::sim {
namespace {

constexpr double kRes = 0.05;
constexpr double kNeatoRange = 5.0;  // NeatoLaserParams::range_max
const Box& kInterior = kCorridorInterior;

// The cell states of the column at x from `margin` south to `margin` north of
// the corridor's interior (the walls are 0.3 m thick).
std::vector<CellState> column(const OccupancyGrid& g, double x, double margin = 0.5) {
  std::vector<CellState> states;
  for (double y = kInterior.y0 - margin + 0.5 * kRes; y < kInterior.y1 + margin; y += kRes) {
    states.push_back(g.state(g.worldToCell(x, y)));
  }
  return states;
}

// Start x of each run of columns in [x0, x1) whose corridor and walls differ
// from `plain`'s (column(g, x, 0.3)), looking only at the south (north =
// false) or north half of the column.
std::vector<double> featureStarts(const OccupancyGrid& g, double x0, double x1, bool north,
                                  const std::vector<CellState>& plain) {
  std::vector<double> starts;
  bool in_feature = false;
  const std::size_t half = plain.size() / 2;
  for (double x = x0 + 0.5 * kRes; x < x1; x += kRes) {
    const std::vector<CellState> c = column(g, x, 0.3);
    const bool differs = north ? !std::equal(c.begin() + half, c.end(), plain.begin() + half)
                               : !std::equal(c.begin(), c.begin() + half, plain.begin());
    if (differs && !in_feature) starts.push_back(x);
    in_feature = differs;
  }
  return starts;
}

TEST(CorridorMapTest, SmallGridWithTightBounds) {
  const OccupancyGrid g = makeCorridorMap();
  EXPECT_DOUBLE_EQ(g.resolution(), kRes);
  EXPECT_LT(g.data().size(), 200000u);
  // The known cells reach to within 0.25 m of every edge of the grid.
  int x_lo = g.width(), x_hi = -1, y_lo = g.height(), y_hi = -1;
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      if (g.state({x, y}) == CellState::kUnknown) continue;
      x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
      y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
    }
  }
  EXPECT_LE(x_lo, 5);
  EXPECT_LE(y_lo, 5);
  EXPECT_GE(x_hi, g.width() - 6);
  EXPECT_GE(y_hi, g.height() - 6);
}

TEST(CorridorMapTest, StraightCorridorBetweenTwoDifferentEnds) {
  const OccupancyGrid g = makeCorridorMap();
  EXPECT_GE(kInterior.x1 - kInterior.x0, 35.0);
  const double width = kInterior.y1 - kInterior.y0;
  EXPECT_GE(width, 2.0);
  EXPECT_LE(width, 2.5);
  // Along its whole length a 2 m band is clear: straight, nothing in the way.
  for (double x = kInterior.x0 + 0.5 * kRes; x < kInterior.x1; x += kRes) {
    for (double y = kInterior.y0 + 0.1 + 0.5 * kRes; y < kInterior.y1 - 0.1; y += kRes) {
      ASSERT_TRUE(g.isFreeAt(x, y)) << "at " << x << ", " << y;
    }
  }
  // Beyond each end the free space is much wider than the corridor (a room,
  // a T-junction), and the two ends look different from the corridor's axis.
  const auto free_across = [&](double x) {
    int n = 0;
    for (double y = 0.5 * kRes; y < 8.0; y += kRes) n += g.isFreeAt(x, y);
    return n * kRes;
  };
  EXPECT_GT(free_across(kInterior.x0 - 1.0), 2.5 * width);
  EXPECT_GT(free_across(kInterior.x1 + 1.1), 2.5 * width);
  const RayCaster caster(g);
  const double axis = 0.5 * (kInterior.y0 + kInterior.y1);
  const double room_depth = caster.cast(kInterior.x0, axis, M_PI, 10.0);
  const double junction_depth = caster.cast(kInterior.x1, axis, 0.0, 10.0);
  EXPECT_GT(room_depth - junction_depth, 1.0);
  EXPECT_GT(junction_depth, 2.0);
}

TEST(CorridorMapTest, FeaturelessStretchLooksTheSameAllAlong) {
  const OccupancyGrid g = makeCorridorMap();
  const double from = kCorridorFeaturelessFrom, to = kInterior.x1;
  ASSERT_GE(to - from, 12.0);
  // Every column is the same: a free corridor between two solid walls.
  const std::vector<CellState> plain = column(g, from + 0.5 * kRes, 0.3);
  const int inside = std::count(plain.begin(), plain.end(), CellState::kFree);
  EXPECT_EQ(inside, std::lround((kInterior.y1 - kInterior.y0) / kRes));
  EXPECT_EQ(std::count(plain.begin(), plain.end(), CellState::kOccupied), 2 * 6);  // 0.3 m walls
  for (double x = from + 0.5 * kRes; x < to; x += kRes) {
    ASSERT_EQ(column(g, x, 0.3), plain) << "at x " << x;
  }
  // So where both of its ends are out of range, a scan from anywhere on the
  // same line across the corridor is the same scan, to the micrometre.
  const RayCaster caster(g);
  const double lo = from + kNeatoRange, hi = to - kNeatoRange;
  ASSERT_GE(hi - lo, 2.0);
  for (const double y : {kInterior.y0 + 0.4, 0.5 * (kInterior.y0 + kInterior.y1)}) {
    for (int beam = 0; beam < 360; ++beam) {
      const double angle = beam * M_PI / 180.0 + 0.3;
      const double first = caster.cast(lo, y, angle, kNeatoRange);
      for (double x = lo; x <= hi; x += 0.137) {
        const double r = caster.cast(x, y, angle, kNeatoRange);
        if (std::isinf(first)) {
          ASSERT_TRUE(std::isinf(r)) << "x " << x << " beam " << beam;
        } else {
          ASSERT_NEAR(r, first, 1e-6) << "x " << x << " beam " << beam;
        }
      }
    }
  }
}

TEST(CorridorMapTest, DoorsStretchHasFeaturesAtIrregularSpacing) {
  const OccupancyGrid g = makeCorridorMap();
  const std::vector<CellState> plain = column(g, kCorridorFeaturelessFrom + 1.0, 0.3);
  for (const bool north : {false, true}) {
    const std::vector<double> starts =
        featureStarts(g, kInterior.x0 + 0.5, kCorridorFeaturelessFrom, north, plain);
    ASSERT_GE(starts.size(), 4u) << (north ? "north" : "south");
    std::set<long> spacings;  // in cells
    for (std::size_t i = 1; i < starts.size(); ++i) {
      spacings.insert(std::lround((starts[i] - starts[i - 1]) / kRes));
    }
    EXPECT_EQ(spacings.size(), starts.size() - 1)
        << "two gaps alike on the " << (north ? "north" : "south");
  }
  // Open doors: from the corridor's axis, a ray across the corridor through
  // a door reaches into a room, more than 1.5 m beyond the wall.
  const RayCaster caster(g);
  const double axis = 0.5 * (kInterior.y0 + kInterior.y1);
  int open_doors = 0, recesses = 0;
  for (const double angle : {-M_PI / 2, M_PI / 2}) {
    bool in_door = false, in_recess = false;
    for (double x = kInterior.x0 + 0.5; x < kCorridorFeaturelessFrom; x += kRes) {
      const double r = caster.cast(x, axis, angle, 10.0);
      const double depth = r - 0.5 * (kInterior.y1 - kInterior.y0);
      const bool door = depth > 1.5, recess = depth > 0.1 && depth < 0.5;
      open_doors += door && !in_door;
      recesses += recess && !in_recess;
      in_door = door, in_recess = recess;
    }
  }
  EXPECT_GE(open_doors, 3);
  EXPECT_GE(recesses, 4);
}

TEST(CorridorMapTest, ClosedAndAllOneSpace) {
  const OccupancyGrid g = makeCorridorMap();
  // Every free cell is reachable from the west room through free cells, and
  // none touches unknown space or the edge (a ray would leave the map).
  ASSERT_TRUE(g.isFreeAt(2.5, 3.95));
  const int reached = test::closedRegionSize(g, 2.5, 3.95);
  ASSERT_GT(reached, 0) << "the free space leaks into unknown space or off the map";
  EXPECT_EQ(reached, static_cast<int>(g.freeCells().size()));
}

}  // namespace
}  // namespace pf::sim
