// The warehouse map (makeWarehouseMap) has what the warehouse bags rely on:
// identical rows and aisles that a lidar cannot tell apart from inside,
// edges that differ (the loading dock, the pillars, the office), free aisles
// for the robot, and pallets that the lidar sees and the map does not.
#include "pf_localization/sim/warehouse_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pf_localization/sim/amr_rig.h"
#include "pf_localization/sim/planar_lidar.h"
#include "support/closed_region.h"

namespace pf::sim {
namespace {

constexpr double kRes = 0.05;

const OccupancyGrid& warehouse() {
  static const OccupancyGrid g = makeWarehouseMap();
  return g;
}

using test::closedRegionSize;

// The number of cells that differ between the window of `w` x `h` cells
// whose south-west cell holds (ax, ay) and the one holding (bx, by); the
// occupied cells of the first are counted into `occupied`.
int differingCells(const OccupancyGrid& g, double ax, double ay, double bx, double by, int w, int h,
                   int* occupied) {
  const CellIndex a = g.worldToCell(ax, ay), b = g.worldToCell(bx, by);
  int differing = 0;
  *occupied = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int8_t va = g.data()[g.linearIndex({a.x + x, a.y + y})];
      differing += va != g.data()[g.linearIndex({b.x + x, b.y + y})];
      *occupied += va == 100;
    }
  }
  return differing;
}

TEST(WarehouseMapTest, Geometry) {
  const OccupancyGrid& g = warehouse();
  EXPECT_EQ(g.width(), 2400);
  EXPECT_EQ(g.height(), 1600);
  EXPECT_DOUBLE_EQ(g.resolution(), kRes);
  EXPECT_DOUBLE_EQ(g.origin().x, kWarehouseExtent.x0);
  EXPECT_DOUBLE_EQ(g.origin().y, kWarehouseExtent.y0);
  EXPECT_EQ(g.state(g.worldToCell(-0.5, 40.0)), CellState::kUnknown);   // outside the walls
  EXPECT_EQ(g.state(g.worldToCell(0.15, 40.0)), CellState::kOccupied);  // the west wall
}

TEST(WarehouseMapTest, ClosedAndEveryAisleReachable) {
  const OccupancyGrid& g = warehouse();
  const int reachable = closedRegionSize(g, 5.0, 6.0);  // the staging area
  ASSERT_GT(reachable, 0) << "the free space leaks into unknown space";
  for (int a = 1; a <= kWarehouseAisles; ++a) {
    const Box aisle = warehouseAisle(a);
    EXPECT_EQ(closedRegionSize(g, 60.0, 0.5 * (aisle.y0 + aisle.y1)), reachable) << "aisle " << a;
  }
  EXPECT_EQ(closedRegionSize(g, 110.0, 75.0), reachable);  // the office, through its door
  // Only the cells between the uprights and the meshes are cut off.
  EXPECT_GT(reachable, 0.9 * g.freeCells().size());
}

TEST(WarehouseMapTest, AislesAreThreeMetresAndFreeEndToEnd) {
  const OccupancyGrid& g = warehouse();
  for (int a = 1; a <= kWarehouseAisles; ++a) {
    const Box aisle = warehouseAisle(a);
    EXPECT_NEAR(aisle.y1 - aisle.y0, 3.0, 1e-9);
    EXPECT_GT(aisle.x1 - aisle.x0, 95.0);
    int blocked = 0;
    for (double y = aisle.y0 + 0.5 * kRes; y < aisle.y1; y += kRes) {
      for (double x = aisle.x0 + 0.5 * kRes; x < aisle.x1; x += kRes) blocked += !g.isFreeAt(x, y);
    }
    EXPECT_EQ(blocked, 0) << "aisle " << a;
    // Bounded by rack faces: uprights on both sides at the first bay.
    EXPECT_FALSE(g.isFreeAt(aisle.x0 + 0.05, aisle.y0 - 0.05)) << "aisle " << a;
    EXPECT_FALSE(g.isFreeAt(aisle.x0 + 0.05, aisle.y1 + 0.05)) << "aisle " << a;
  }
}

TEST(WarehouseMapTest, TheTwinAislesAndTheirRowsAreIdenticalWallToWall) {
  const OccupancyGrid& g = warehouse();
  // Aisle a with the rows on either side, across the whole hall (walls included).
  const int w = g.width(), h = std::lround((kWarehouseRowPitch + kWarehouseRowDepth) / kRes);
  const double x = kWarehouseExtent.x0 + 0.5 * kRes;
  const double y1 = warehouseRowY(0) + 0.5 * kRes;
  for (int a = 2; a <= kWarehouseAisles; ++a) {
    int occupied = 0;
    EXPECT_EQ(differingCells(g, x, warehouseRowY(a - 1) + 0.5 * kRes, x, y1, w, h, &occupied), 0)
        << "aisle " << a << " differs from aisle 1";
    // Uprights: 12 a segment on each of four lines, in two rows and three
    // segments, plus the meshes and the walls: racks, not empty floor.
    EXPECT_GT(occupied, 2 * 3 * 4 * 12 * 4) << "aisle " << a;
  }
  // And the segments of a row are identical too.
  const int segment = std::lround(kWarehouseSegmentLength / kRes);
  const int row = std::lround(kWarehouseRowDepth / kRes);
  for (double sx : {kWarehouseSegmentX[1], kWarehouseSegmentX[2]}) {
    int occupied = 0;
    EXPECT_EQ(differingCells(g, sx + 0.5 * kRes, warehouseRowY(5) + 0.5 * kRes,
                             kWarehouseSegmentX[0] + 0.5 * kRes, warehouseRowY(5) + 0.5 * kRes,
                             segment, row, &occupied),
              0)
        << "segment at x " << sx;
    EXPECT_GT(occupied, std::lround(kWarehouseSegmentLength / kRes));  // the mesh at least
  }
}

TEST(WarehouseMapTest, TheEdgesDifferAndTheHallIsNotSymmetric) {
  const OccupancyGrid& g = warehouse();
  // The loading dock: door recesses in the south wall, at irregular spacing.
  std::vector<double> door_starts;
  bool in_door = false;
  for (double x = 0.5 * kRes; x < 118.0; x += kRes) {
    const bool door = g.isFreeAt(x, 0.0);  // inside the south wall's line
    if (door && !in_door) door_starts.push_back(x);
    in_door = door;
  }
  ASSERT_GE(door_starts.size(), 5u);
  std::vector<double> gaps;
  for (std::size_t i = 1; i < door_starts.size(); ++i) {
    gaps.push_back(door_starts[i] - door_starts[i - 1]);
  }
  EXPECT_GT(
      *std::max_element(gaps.begin(), gaps.end()) - *std::min_element(gaps.begin(), gaps.end()),
      3.0);
  // Pillars in the staging area, and the office's wall with its door.
  int pillars = 0;
  for (double x = 0.5 * kRes; x < 118.0; x += kRes) pillars += !g.isFreeAt(x, 7.25);
  EXPECT_GE(pillars, 3 * 10);   // at least three 0.5 m pillars
  EXPECT_LE(pillars, 10 * 10);  // and not a wall
  EXPECT_FALSE(g.isFreeAt(102.0, 71.05));
  EXPECT_TRUE(g.isFreeAt(104.5, 71.05));
  // The rack block is symmetric under a half turn about its centre; the hall
  // is not: its half turn differs from it in thousands of cells.
  int differing = 0;
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      differing += g.data()[g.linearIndex({x, y})] !=
                   g.data()[g.linearIndex({g.width() - 1 - x, g.height() - 1 - y})];
    }
  }
  EXPECT_GT(differing, 2000);
}

TEST(WarehouseMapTest, PalletsStandInFreeSpaceOffTheMap) {
  const OccupancyGrid& g = warehouse();
  const std::vector<Box3> pallets = warehousePallets();
  ASSERT_GE(pallets.size(), 3u);
  for (const Box3& p : pallets) {
    for (double x = p.x0; x <= p.x1; x += 0.5 * kRes) {
      for (double y = p.y0; y <= p.y1; y += 0.5 * kRes) {
        ASSERT_TRUE(g.isFreeAt(x, y)) << "pallet at " << p.x0 << ", " << p.y0;
      }
    }
    EXPECT_GT(p.z1, 0.2);  // tall enough for the rig's lidar, 0.2 m up, to see
  }
}

// The rig's lidar in the warehouse: the twin aisles look the same to it, the
// edge of the rack block is what tells them apart, and it sees the pallets
// that the map lacks.
TEST(WarehouseMapTest, TheRigsLidarSeesTwinAislesAlikeAndThePalletsTheMapLacks) {
  const OccupancyGrid& g = warehouse();
  const RayCaster walls(g);
  const PlanarLidar lidar = amrWarehouseLidar({100'000'000, 0});
  const auto centre = [](int a) {
    const Box aisle = warehouseAisle(a);
    return 0.5 * (aisle.y0 + aisle.y1);
  };
  // Mid-aisle, middle segment, facing west: aisles 2 and 8 read the same.
  const auto in2 = idealRanges(lidar, walls, {}, {58.9, centre(2), M_PI}, 0.0);
  const auto in8 = idealRanges(lidar, walls, {}, {58.9, centre(8), M_PI}, 0.0);
  int returns = 0;
  for (int i = 0; i < lidar.beams; ++i) {
    if (std::isinf(in2[i])) {
      EXPECT_TRUE(std::isinf(in8[i])) << "beam " << i;
    } else {
      EXPECT_NEAR(in2[i], in8[i], 1e-6) << "beam " << i;
      ++returns;
    }
  }
  EXPECT_GT(returns, lidar.beams / 2);
  // In cross aisle 1, facing south: from aisle 5 the beams down the cross
  // aisle end on the ends of rows 0-4, the nearest of them 23 m away; from
  // aisle 4, 5.4 m further south, the same beams find rows one further
  // south, and the ones that found row 0 pass the block's edge (20 m away).
  const double cross_x =
      0.5 * (kWarehouseSegmentX[0] + kWarehouseSegmentLength + kWarehouseSegmentX[1]);
  const auto at4 = idealRanges(lidar, walls, {}, {cross_x, centre(4), -M_PI / 2}, 0.0);
  const auto at5 = idealRanges(lidar, walls, {}, {cross_x, centre(5), -M_PI / 2}, 0.0);
  int differing = 0;
  for (int i = 0; i < lidar.beams; ++i) {
    differing += !(std::isinf(at4[i]) && std::isinf(at5[i])) && std::fabs(at4[i] - at5[i]) > 0.01;
  }
  EXPECT_GT(differing, 0);

  // The first pallet, seen from the middle of its aisle: the map has
  // nothing there, the scene does.
  const Box3 pallet = warehousePallets()[0];
  const Pose2 base{pallet.x0 - 3.0, pallet.y1 + 0.6, 0.0};
  const Scene3D scene(g, std::numeric_limits<double>::infinity(), warehousePallets(), {});
  const auto on_map = idealRanges(lidar, walls, {}, base, 0.0);
  const auto seen = idealRanges(lidar, scene, base, 0.0);
  int shorter = 0;
  for (int i = 0; i < lidar.beams; ++i) shorter += seen[i] < on_map[i] - 0.1;
  EXPECT_GT(shorter, 10);
}

}  // namespace
}  // namespace pf::sim
