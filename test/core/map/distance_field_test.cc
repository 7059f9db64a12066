#include "pf_localization/core/map/distance_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pf_localization/core/map/distance_transform.h"

namespace pf {
namespace {

constexpr double kTol = 1e-6;  // distances are stored as float

// 5 x 4 cells of 0.5 m, all free but one obstacle at cell (1, 1).
OccupancyGrid oneObstacle(const Pose2& origin = {}) {
  std::vector<int8_t> data(20, 0);
  data[1 * 5 + 1] = 100;
  return OccupancyGrid(5, 4, 0.5, origin, data);
}

TEST(DistanceField, DistancesAreInMetres) {
  const DistanceField field(oneObstacle(), 10.0);
  // Squared cell distances to (1, 1) times the 0.5 m resolution.
  EXPECT_NEAR(0.0, field.distance({1, 1}), kTol);
  EXPECT_NEAR(0.5, field.distance({2, 1}), kTol);
  EXPECT_NEAR(0.5, field.distance({1, 0}), kTol);
  EXPECT_NEAR(0.5 * std::sqrt(2.0), field.distance({0, 0}), kTol);
  EXPECT_NEAR(1.5, field.distance({4, 1}), kTol);
  EXPECT_NEAR(0.5 * std::sqrt(13.0), field.distance({4, 3}), kTol);  // (3^2 + 2^2)
  ASSERT_EQ(20u, field.size());
  EXPECT_NEAR(0.5 * std::sqrt(13.0), field.distance(std::size_t{3 * 5 + 4}), kTol);
}

TEST(DistanceField, InsideAThickObstacleTheSurfaceDistanceIsHowFarPastItsSurface) {
  // 9 x 3 cells of 0.1 m: a wall 6 cells thick (x 1-6) between free cells.
  std::vector<int8_t> data(27, 0);
  for (int y = 0; y < 3; ++y) {
    for (int x = 1; x <= 6; ++x) data[y * 9 + x] = 100;
  }
  const DistanceField field(OccupancyGrid(9, 3, 0.1, {}, data), 2.0);
  const auto at = [&field](int x) { return field.surfaceDistance(1 * 9 + x); };
  // The surface cells and the next (kFreeDepth) are on the wall ...
  EXPECT_NEAR(0.0, at(1), kTol);
  EXPECT_NEAR(0.0, at(2), kTol);
  EXPECT_NEAR(0.0, at(6), kTol);
  // ... a cell three deep is one cell past that: a beam ending there went
  // through the wall's face by that much more than the map's blur allows.
  EXPECT_NEAR(0.1, at(3), kTol);
  EXPECT_NEAR(0.1, at(4), kTol);
  // Outside, the distance to the nearest occupied cell as always; and the
  // likelihood field's own distances are 0 on every occupied cell.
  EXPECT_NEAR(0.1, at(0), kTol);
  EXPECT_NEAR(0.2, at(8), kTol);
  EXPECT_NEAR(0.0, field.distance({3, 1}), kTol);
}

// The float's bits: +0.0f and -0.0f compare equal, but the likelihood
// table's memo keys on the bits.
uint32_t bitsOf(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

TEST(DistanceField, OneArrayHoldsBothTheDistanceAndTheSurfaceDistance) {
  // 16 x 12 cells of 0.1 m: a block 10 x 8 cells (x 3-12, y 2-9), whose
  // middle lies up to four cells deep, beside a wall one cell thick (x 14).
  const int w = 16, h = 12;
  std::vector<int8_t> data(w * h, 0);
  std::vector<bool> occupied(w * h, false);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if ((x >= 3 && x <= 12 && y >= 2 && y <= 9) || x == 14) {
        data[y * w + x] = 100;
        occupied[y * w + x] = true;
      }
    }
  }
  const double res = 0.1, cap = 2.0;
  const DistanceField field(OccupancyGrid(w, h, res, {}, data), cap);
  ASSERT_EQ(static_cast<std::size_t>(w * h), field.size());
  const auto nearest = [&](int x, int y, bool want_occupied) {
    double best = std::numeric_limits<double>::infinity();
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if (occupied[v * w + u] == want_occupied) best = std::min(best, std::hypot(u - x, v - y));
      }
    }
    return best;
  };
  int deep = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = y * w + x;
      if (occupied[i]) {
        // The distance is +0.0f to the bit; the surface distance the depth
        // past the surface less the surface cell and kFreeDepth.
        EXPECT_EQ(bitsOf(0.0f), bitsOf(field.distance(i))) << x << ", " << y;
        EXPECT_EQ(0.0, field.distance({x, y}));
        const double depth = std::min(
            std::max(nearest(x, y, false) - 1.0 - DistanceField::kFreeDepth, 0.0) * res, cap);
        EXPECT_NEAR(depth, field.surfaceDistance(i), kTol) << x << ", " << y;
        EXPECT_FALSE(std::signbit(field.surfaceDistance(i)));
        if (depth > 0.0) ++deep;
      } else {
        // Off obstacles the two are one value, the distance, > 0.
        const double d = std::min(nearest(x, y, true) * res, cap);
        EXPECT_NEAR(d, field.distance(i), kTol) << x << ", " << y;
        EXPECT_EQ(bitsOf(field.distance(i)), bitsOf(field.surfaceDistance(i)));
        EXPECT_GT(field.distance(i), 0.0f);
      }
    }
  }
  // The block's middle, 6 x 4 cells three or four deep (x 5-10, y 4-7): one
  // or two cells past the surface less kFreeDepth.
  EXPECT_EQ(6 * 4, deep);
  EXPECT_NEAR(0.2, field.surfaceDistance(5 * w + 7), kTol);  // 4 cells deep
  EXPECT_NEAR(0.1, field.surfaceDistance(4 * w + 6), kTol);  // 3 cells deep
}

TEST(DistanceField, DistancesAreCappedAtMaxDistance) {
  const DistanceField field(oneObstacle(), 1.0);
  EXPECT_EQ(1.0, field.maxDistance());
  EXPECT_NEAR(0.5 * std::sqrt(2.0), field.distance({0, 0}), kTol);  // below the cap
  EXPECT_NEAR(1.0, field.distance({3, 1}), kTol);                   // exactly 2 cells
  EXPECT_NEAR(1.0, field.distance({4, 1}), kTol);                   // 1.5 m, capped
  EXPECT_NEAR(1.0, field.distance({4, 3}), kTol);                   // 1.80 m, capped
  for (std::size_t i = 0; i < field.size(); ++i) EXPECT_LE(field.surfaceDistance(i), 1.0f);
}

TEST(DistanceField, NoObstacleIsMaxDistanceEverywhere) {
  const DistanceField field(OccupancyGrid(5, 4, 0.5, {}, std::vector<int8_t>(20, 0)), 2.0);
  for (std::size_t i = 0; i < field.size(); ++i) {
    EXPECT_EQ(2.0f, field.distance(i));
    EXPECT_EQ(2.0f, field.surfaceDistance(i));
  }
}

TEST(DistanceField, UnknownCellsAreNotObstacles) {
  // -1 (unknown) and 50 (between free and occupied) next to the obstacle,
  // 64 just below the occupied threshold, 65 just at it.
  std::vector<int8_t> data(20, 0);
  data[1 * 5 + 1] = 100;
  data[1 * 5 + 2] = -1;
  data[2 * 5 + 1] = 50;
  data[0 * 5 + 4] = 64;
  data[3 * 5 + 4] = 65;
  const DistanceField field(OccupancyGrid(5, 4, 0.5, {}, data), 10.0);
  EXPECT_NEAR(0.5, field.distance({2, 1}), kTol);  // unknown: 1 cell away
  EXPECT_NEAR(0.5, field.distance({1, 2}), kTol);  // grey: 1 cell away
  EXPECT_NEAR(1.5, field.distance({4, 0}), kTol);  // 64 is not: 3 cells below the 65
  EXPECT_NEAR(0.0, field.distance({4, 3}), kTol);  // 65 is an obstacle
  EXPECT_NEAR(0.5, field.distance({4, 2}), kTol);  // next to the 65
}

TEST(DistanceField, OutsideTheMapIsMaxDistance) {
  const DistanceField field(oneObstacle(), 1.2);
  EXPECT_EQ(1.2, field.distance({-1, 0}));
  EXPECT_EQ(1.2, field.distance({0, -1}));
  EXPECT_EQ(1.2, field.distance({5, 0}));
  EXPECT_EQ(1.2, field.distance({0, 4}));
  EXPECT_EQ(1.2, field.distance({-1000000, 1000000}));
  // Just outside the map next to the obstacle is still "far": nothing is
  // known there.
  EXPECT_EQ(1.2, field.distanceAt(-0.1, 0.75));
  EXPECT_EQ(1.2, field.distanceAt(0.75, -0.01));
  EXPECT_EQ(1.2, field.distanceAt(2.6, 0.25));
  EXPECT_EQ(1.2, field.distanceAt(0.25, 2.01));
}

TEST(DistanceField, DistanceAtUsesWorldCoordinates) {
  const DistanceField field(oneObstacle({-1.0, 2.0, 0.0}), 10.0);
  // Cell (0, 0) spans [-1, -0.5) x [2, 2.5); the obstacle cell (1, 1) is
  // [-0.5, 0) x [2.5, 3).
  EXPECT_NEAR(0.0, field.distanceAt(-0.25, 2.75), kTol);
  EXPECT_NEAR(0.0, field.distanceAt(-0.49, 2.51), kTol);
  EXPECT_NEAR(0.5 * std::sqrt(2.0), field.distanceAt(-0.9, 2.1), kTol);
  EXPECT_NEAR(0.5 * std::sqrt(13.0), field.distanceAt(1.4, 3.9), kTol);
  EXPECT_EQ(10.0, field.distanceAt(0.25, 0.25));  // outside, under the shifted origin
}

TEST(DistanceField, RotatedOriginIsHonoured) {
  // The map's x axis points along world +y: cell (i, j) has its centre at
  // (1 - (j + 0.5) * 0.5, 2 + (i + 0.5) * 0.5).
  const DistanceField field(oneObstacle({1.0, 2.0, M_PI / 2}), 10.0);
  EXPECT_NEAR(0.0, field.distanceAt(1.0 - 0.75, 2.0 + 0.75), kTol);  // cell (1, 1)
  EXPECT_NEAR(0.5 * std::sqrt(13.0), field.distanceAt(1.0 - 1.75, 2.0 + 2.25), kTol);  // (4, 3)
  EXPECT_NEAR(1.5, field.distanceAt(1.0 - 0.75, 2.0 + 2.25), kTol);  // cell (4, 1)
  // In the unrotated frame this point would be in the map; here it is not.
  EXPECT_EQ(10.0, field.distanceAt(1.75, 2.25));
}

TEST(DistanceField, InvalidMaxDistanceThrows) {
  const OccupancyGrid grid = oneObstacle();
  EXPECT_THROW(DistanceField(grid, 0.0), std::invalid_argument);
  EXPECT_THROW(DistanceField(grid, -1.0), std::invalid_argument);
  EXPECT_THROW(DistanceField(grid, std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(DistanceField(grid, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_NO_THROW(DistanceField(grid, 1e-3));
  // 0.5 m cells: 1 024 m is 2 048 cells, the most the field lists.
  EXPECT_NO_THROW(DistanceField(grid, 1024.0));
  EXPECT_THROW(DistanceField(grid, 1024.5), std::invalid_argument);
}

TEST(DistanceField, RowsLongerThanTheTransformTakesAreRefused) {
  const auto row = [](int width) {
    std::vector<int8_t> data(static_cast<std::size_t>(width), 0);
    data[0] = 100;
    return OccupancyGrid(width, 1, 0.05, {}, data);
  };
  EXPECT_NO_THROW(DistanceField(row(kMaxRowPassCells), 0.2));
  EXPECT_THROW(DistanceField(row(kMaxRowPassCells + 1), 0.2), std::invalid_argument);
}

TEST(DistanceField, FewClassesHoldEveryValueExactly) {
  // A wall and a block on 120 x 90 cells of 2 cm with the default 2 m cap
  // (100 cells): each cell's value is the formula's, to the bit, from a
  // table of the distinct values.
  const int w = 120, h = 90;
  std::vector<int8_t> data(w * h, 0);
  for (int x = 10; x < 110; ++x) data[40 * w + x] = 100;
  for (int y = 60; y < 80; ++y) {
    for (int x = 70; x < 100; ++x) data[y * w + x] = 100;
  }
  const double res = 0.02;
  const DistanceField field(OccupancyGrid(w, h, res, {}, data), 2.0);
  EXPECT_LT(field.classDistances().size(), 6000u);  // 5 597: the distances, and the depths
  for (int y = 0; y < h; y += 7) {
    for (int x = 0; x < w; x += 3) {
      double best = std::numeric_limits<double>::infinity();
      for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
          if (data[v * w + u] == 100)
            best = std::min<double>(best, (u - x) * (u - x) + (v - y) * (v - y));
        }
      }
      const float expected = std::min(std::sqrt(static_cast<float>(best)) * 0.02f, 2.0f);
      EXPECT_EQ(bitsOf(expected), bitsOf(field.distance(static_cast<std::size_t>(y * w + x))))
          << x << ", " << y;
    }
  }
}

TEST(DistanceField, PastSixtyFiveThousandValuesNeighboursShareAClass) {
  // A 1 000-cell cap lists some 200 000 values: runs of neighbours share a
  // class, each off by less than a thousandth of the cap.
  const int w = 700, h = 3;
  std::vector<int8_t> data(w * h, 0);
  data[1 * w + 0] = 100;
  const double cap = 1000 * 0.01;
  const DistanceField field(OccupancyGrid(w, h, 0.01, {}, data), cap);
  EXPECT_EQ(DistanceField::kMaxClasses, field.classDistances().size());
  for (int x = 0; x < w; x += 13) {
    EXPECT_NEAR(std::hypot(x, 0) * 0.01, field.distance(static_cast<std::size_t>(w + x)),
                1e-3 * cap);
    EXPECT_NEAR(std::hypot(x, 1) * 0.01, field.distance(static_cast<std::size_t>(x)), 1e-3 * cap);
  }
  EXPECT_EQ(0.0f, field.distance(static_cast<std::size_t>(w)));
}

}  // namespace
}  // namespace pf
