#include "pf_localization/core/map/occupancy_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace pf {
namespace {

TEST(OccupancyGridTest, ClassifyUsesTheThreeBands) {
  EXPECT_EQ(OccupancyGrid::classify(-128), CellState::kUnknown);
  EXPECT_EQ(OccupancyGrid::classify(-1), CellState::kUnknown);
  EXPECT_EQ(OccupancyGrid::classify(0), CellState::kFree);
  EXPECT_EQ(OccupancyGrid::classify(19), CellState::kFree);
  EXPECT_EQ(OccupancyGrid::classify(20), CellState::kUnknown);
  EXPECT_EQ(OccupancyGrid::classify(64), CellState::kUnknown);
  EXPECT_EQ(OccupancyGrid::classify(65), CellState::kOccupied);
  EXPECT_EQ(OccupancyGrid::classify(100), CellState::kOccupied);
  EXPECT_EQ(OccupancyGrid::classify(127), CellState::kOccupied);
}

TEST(OccupancyGridTest, DefaultIsEmpty) {
  const OccupancyGrid g;
  EXPECT_TRUE(g.empty());
  EXPECT_FALSE(g.contains({0, 0}));
  EXPECT_TRUE(g.freeCells().empty());
}

TEST(OccupancyGridTest, KeepsWhatItWasGiven) {
  const OccupancyGrid g(3, 2, 0.25, {1.0, -2.0, 0.5}, {0, 100, -1, 19, 20, 65});
  EXPECT_FALSE(g.empty());
  EXPECT_EQ(g.width(), 3);
  EXPECT_EQ(g.height(), 2);
  EXPECT_EQ(g.resolution(), 0.25);
  EXPECT_EQ(g.origin().x, 1.0);
  EXPECT_EQ(g.origin().y, -2.0);
  EXPECT_EQ(g.origin().yaw, 0.5);
  EXPECT_EQ(g.data(), std::vector<int8_t>({0, 100, -1, 19, 20, 65}));
}

TEST(OccupancyGridTest, FreeCellsAndStates) {
  // Row-major from the lower-left: row 0 is {0, 100, -1}, row 1 is {19, 20, 65}.
  const OccupancyGrid g(3, 2, 1.0, {}, {0, 100, -1, 19, 20, 65});
  ASSERT_EQ(2u, g.freeCells().size());
  EXPECT_EQ(0, g.freeCells()[0]);
  EXPECT_EQ(3, g.freeCells()[1]);
  EXPECT_EQ(g.state({0, 0}), CellState::kFree);
  EXPECT_EQ(g.state({1, 0}), CellState::kOccupied);
  EXPECT_EQ(g.state({2, 0}), CellState::kUnknown);
  EXPECT_EQ(g.state({0, 1}), CellState::kFree);
  EXPECT_EQ(g.state({1, 1}), CellState::kUnknown);
  EXPECT_EQ(g.state({2, 1}), CellState::kOccupied);
  EXPECT_EQ(g.state({-1, 0}), CellState::kUnknown);
  EXPECT_EQ(g.state({3, 0}), CellState::kUnknown);
  EXPECT_EQ(g.state({0, 2}), CellState::kUnknown);
  EXPECT_EQ(g.linearIndex({2, 1}), 5);
}

TEST(OccupancyGridTest, Contains) {
  const OccupancyGrid g(3, 2, 1.0, {}, std::vector<int8_t>(6, 0));
  EXPECT_TRUE(g.contains({0, 0}));
  EXPECT_TRUE(g.contains({2, 1}));
  EXPECT_FALSE(g.contains({-1, 0}));
  EXPECT_FALSE(g.contains({0, -1}));
  EXPECT_FALSE(g.contains({3, 0}));
  EXPECT_FALSE(g.contains({0, 2}));
}

TEST(OccupancyGridTest, WorldToCellWithAnOffsetOrigin) {
  // 4 x 3 cells of 0.5 m whose lower-left corner is at (-1, 2).
  const OccupancyGrid g(4, 3, 0.5, {-1.0, 2.0, 0.0}, std::vector<int8_t>(12, 0));
  auto cell = [&](double x, double y) {
    const CellIndex c = g.worldToCell(x, y);
    return std::vector<int>{c.x, c.y};
  };
  EXPECT_EQ(cell(-1.0, 2.0), std::vector<int>({0, 0}));
  EXPECT_EQ(cell(-0.75, 2.25), std::vector<int>({0, 0}));
  EXPECT_EQ(cell(-0.5, 2.5), std::vector<int>({1, 1}));
  EXPECT_EQ(cell(0.9, 3.4), std::vector<int>({3, 2}));
  // Just outside: floor, not truncation toward zero, so -0.1 cells is cell -1.
  EXPECT_EQ(cell(-1.05, 1.95), std::vector<int>({-1, -1}));
  EXPECT_EQ(cell(1.0, 3.5), std::vector<int>({4, 3}));
  EXPECT_FALSE(g.contains(g.worldToCell(1.0, 3.5)));
}

TEST(OccupancyGridTest, CellToWorldGivesTheCellCentre) {
  const OccupancyGrid g(4, 3, 0.5, {-1.0, 2.0, 0.0}, std::vector<int8_t>(12, 0));
  double x = 0.0, y = 0.0;
  g.cellToWorld({0, 0}, &x, &y);
  EXPECT_EQ(x, -0.75);
  EXPECT_EQ(y, 2.25);
  g.cellToWorld({3, 2}, &x, &y);
  EXPECT_EQ(x, 0.75);
  EXPECT_EQ(y, 3.25);
}

TEST(OccupancyGridTest, RotatedOrigin) {
  // The map's x axis points along world +y: cell (i, j) lies at world
  // (1 - (j + 0.5), 2 + (i + 0.5)) with 1 m cells.
  const OccupancyGrid g(3, 2, 1.0, {1.0, 2.0, M_PI / 2}, std::vector<int8_t>(6, 0));
  double x = 0.0, y = 0.0;
  g.cellToWorld({0, 0}, &x, &y);
  EXPECT_NEAR(x, 0.5, 1e-12);
  EXPECT_NEAR(y, 2.5, 1e-12);
  g.cellToWorld({2, 1}, &x, &y);
  EXPECT_NEAR(x, -0.5, 1e-12);
  EXPECT_NEAR(y, 4.5, 1e-12);

  CellIndex c = g.worldToCell(-0.5, 4.5);
  EXPECT_EQ(c.x, 2);
  EXPECT_EQ(c.y, 1);
  c = g.worldToCell(0.9, 2.1);  // 0.1 m into the map along both map axes
  EXPECT_EQ(c.x, 0);
  EXPECT_EQ(c.y, 0);
  c = g.worldToCell(1.1, 2.1);  // 0.1 m behind the map's y = 0 edge
  EXPECT_EQ(c.x, 0);
  EXPECT_EQ(c.y, -1);
  EXPECT_FALSE(g.contains(c));
}

TEST(OccupancyGridTest, CellToWorldToCellIsTheIdentityForAnyYaw) {
  const OccupancyGrid g(5, 4, 0.05, {-3.0, 7.0, 2.5}, std::vector<int8_t>(20, 0));
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) {
      double x = 0.0, y = 0.0;
      g.cellToWorld({i, j}, &x, &y);
      const CellIndex c = g.worldToCell(x, y);
      EXPECT_EQ(c.x, i);
      EXPECT_EQ(c.y, j);
    }
  }
}

TEST(OccupancyGridTest, IsFreeAt) {
  const OccupancyGrid g(2, 1, 1.0, {10.0, 0.0, 0.0}, {0, 100});
  EXPECT_TRUE(g.isFreeAt(10.5, 0.5));
  EXPECT_FALSE(g.isFreeAt(11.5, 0.5));  // occupied
  EXPECT_FALSE(g.isFreeAt(9.5, 0.5));   // outside
}

TEST(OccupancyGridTest, ConstructorRejectsBadArguments) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<int8_t> four(4, 0);
  EXPECT_THROW(OccupancyGrid(0, 4, 1.0, {}, {}), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(4, 0, 1.0, {}, {}), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(-2, -2, 1.0, {}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, 0.0, {}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, -0.5, {}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, nan, {}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, inf, {}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, 1.0, {nan, 0.0, 0.0}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, 1.0, {0.0, 0.0, inf}, four), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, 1.0, {}, std::vector<int8_t>(3, 0)), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(2, 2, 1.0, {}, std::vector<int8_t>(5, 0)), std::invalid_argument);
  EXPECT_NO_THROW(OccupancyGrid(2, 2, 1.0, {}, four));
}

TEST(OccupancyGridTest, SizeMismatchMessageNamesBothSizes) {
  try {
    OccupancyGrid(2, 3, 1.0, {}, std::vector<int8_t>(5, 0));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "OccupancyGrid: 5 cell values for a 2 x 3 grid");
  }
}

}  // namespace
}  // namespace pf
