#include "pf_localization/sim/building_map.h"

#include <gtest/gtest.h>

#include "support/closed_region.h"

namespace pf::sim {
namespace {

TEST(MapCanvasTest, PaintsCellsWhoseCentresAreInside) {
  MapCanvas c({0.0, 0.0, 0.4, 0.3}, 0.1);  // 4 x 3 cells
  c.fill({0.1, 0.0, 0.3, 0.2}, MapCanvas::kFree);
  c.disc(0.35, 0.25, 0.01, MapCanvas::kOccupied);
  const OccupancyGrid g = c.grid();
  ASSERT_EQ(g.width(), 4);
  ASSERT_EQ(g.height(), 3);
  const std::vector<int8_t> expected = {-1, 0,  0,  -1,  // y 0
                                        -1, 0,  0,  -1,  // y 1
                                        -1, -1, -1, 100};
  EXPECT_EQ(g.data(), expected);
}

using test::closedRegionSize;

TEST(BuildingMapTest, Geometry) {
  const OccupancyGrid g = makeBuildingMap();
  EXPECT_EQ(g.width(), 440);
  EXPECT_EQ(g.height(), 340);
  EXPECT_DOUBLE_EQ(g.resolution(), 0.05);
  EXPECT_DOUBLE_EQ(g.origin().x, -1.0);
  EXPECT_DOUBLE_EQ(g.origin().y, -1.0);
  // Unknown outside the building, in the notch and in the locked closet.
  EXPECT_EQ(g.state(g.worldToCell(-0.5, 7.0)), CellState::kUnknown);
  EXPECT_EQ(g.state(g.worldToCell(18.0, 13.0)), CellState::kUnknown);
  EXPECT_EQ(g.state(g.worldToCell(19.0, 1.0)), CellState::kUnknown);
}

TEST(BuildingMapTest, EveryRoomIsReachableAndTheBuildingIsClosed) {
  const OccupancyGrid g = makeBuildingMap();
  const int reachable = closedRegionSize(g, 2.0, 7.5);  // west end of the corridor
  ASSERT_GT(reachable, 0) << "the free space leaks into unknown space";
  // Every room's free space is the corridor's: one region.
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{{2.0, 10.0},
                                                                   {7.0, 10.0},
                                                                   {12.0, 12.0},
                                                                   {17.0, 10.0},
                                                                   {1.0, 2.0},
                                                                   {10.0, 5.0},
                                                                   {15.0, 5.0}}) {
    EXPECT_EQ(closedRegionSize(g, x, y), reachable) << "at " << x << ", " << y;
  }
  // And it is most of the building's free space: only the cells walled in
  // behind furniture may be cut off.
  EXPECT_GT(reachable, 0.97 * g.freeCells().size());
}

TEST(BuildingMapTest, TwinRoomsAreIdenticalWallsIncluded) {
  const OccupancyGrid g = makeBuildingMap();
  const double wall = 0.15;
  const CellIndex a = g.worldToCell(kTwinRoomA.x0 - wall + 0.025, kTwinRoomA.y0 - wall + 0.025);
  const CellIndex b = g.worldToCell(kTwinRoomB.x0 - wall + 0.025, kTwinRoomB.y0 - wall + 0.025);
  const int w = std::lround((kTwinRoomA.x1 - kTwinRoomA.x0 + 2 * wall) / 0.05);
  const int h = std::lround((kTwinRoomA.y1 - kTwinRoomA.y0 + 2 * wall) / 0.05);
  int free_cells = 0, differing = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int8_t va = g.data()[g.linearIndex({a.x + x, a.y + y})];
      const int8_t vb = g.data()[g.linearIndex({b.x + x, b.y + y})];
      differing += va != vb;
      free_cells += va == 0;
    }
  }
  EXPECT_EQ(differing, 0);
  EXPECT_GT(free_cells, 0.8 * w * h * 0.8);  // a room, not a wall
}

TEST(SmallMapTest, ClosedAndAsymmetric) {
  const OccupancyGrid g = makeSmallMap();
  EXPECT_EQ(g.width(), 140);
  EXPECT_EQ(g.height(), 100);
  const int reachable = closedRegionSize(g, 1.0, 3.0);
  EXPECT_GT(reachable, 0);
  EXPECT_EQ(reachable, static_cast<int>(g.freeCells().size()));
  // No mirror image or half turn of the room matches it.
  const auto at = [&](int x, int y) { return g.data()[y * g.width() + x]; };
  int mirror_x = 0, mirror_y = 0, half_turn = 0;
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      const int fx = g.width() - 1 - x, fy = g.height() - 1 - y;
      mirror_x += at(x, y) != at(fx, y);
      mirror_y += at(x, y) != at(x, fy);
      half_turn += at(x, y) != at(fx, fy);
    }
  }
  EXPECT_GT(mirror_x, 500);
  EXPECT_GT(mirror_y, 500);
  EXPECT_GT(half_turn, 500);
}

}  // namespace
}  // namespace pf::sim
