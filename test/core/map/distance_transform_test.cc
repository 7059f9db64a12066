#include "pf_localization/core/map/distance_transform.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace pf {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Row-major from the lower-left cell, like the grids: index = y * width + x.
std::vector<bool> sources(int width, int height, const std::vector<std::pair<int, int>>& cells) {
  std::vector<bool> is_source(static_cast<std::size_t>(width) * height, false);
  for (const auto& c : cells) is_source[c.second * width + c.first] = true;
  return is_source;
}

std::vector<float> bruteForce(const std::vector<bool>& is_source, int width, int height) {
  std::vector<float> out(is_source.size(), kInf);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int sy = 0; sy < height; ++sy) {
        for (int sx = 0; sx < width; ++sx) {
          if (!is_source[sy * width + sx]) continue;
          const float d = static_cast<float>((x - sx) * (x - sx) + (y - sy) * (y - sy));
          out[y * width + x] = std::min(out[y * width + x], d);
        }
      }
    }
  }
  return out;
}

TEST(SquaredDistanceTransform, OneSource) {
  // 5 x 4, source at (1, 1): (x - 1)^2 + (y - 1)^2.
  const std::vector<float> expected = {
      2, 1, 2, 5, 10,  // y = 0
      1, 0, 1, 4, 9,   // y = 1
      2, 1, 2, 5, 10,  // y = 2
      5, 4, 5, 8, 13,  // y = 3
  };
  EXPECT_EQ(expected, squaredDistanceTransform(sources(5, 4, {{1, 1}}), 5, 4));
}

TEST(SquaredDistanceTransform, TwoSourcesTakeTheNearer) {
  // 5 x 4, sources at (0, 0) and (4, 3): min(x^2 + y^2, (x - 4)^2 + (y - 3)^2).
  // E.g. (3, 0): min(9, 1 + 9) = 9; (2, 2): min(8, 4 + 1) = 5; (1, 3): min(10, 9) = 9.
  const std::vector<float> expected = {
      0, 1, 4, 9, 9,  // y = 0
      1, 2, 5, 5, 4,  // y = 1
      4, 5, 5, 2, 1,  // y = 2
      9, 9, 4, 1, 0,  // y = 3
  };
  EXPECT_EQ(expected, squaredDistanceTransform(sources(5, 4, {{0, 0}, {4, 3}}), 5, 4));
}

TEST(SquaredDistanceTransform, NoSourceIsInfiniteEverywhere) {
  const std::vector<float> d = squaredDistanceTransform(sources(5, 4, {}), 5, 4);
  ASSERT_EQ(20u, d.size());
  for (float v : d) EXPECT_EQ(kInf, v);
}

TEST(SquaredDistanceTransform, AllSourcesIsZeroEverywhere) {
  const std::vector<float> d = squaredDistanceTransform(std::vector<bool>(20, true), 5, 4);
  EXPECT_EQ(std::vector<float>(20, 0.0f), d);
}

TEST(SquaredDistanceTransform, SingleRowAndSingleColumn) {
  // 6 x 1, source at x = 4: (x - 4)^2.
  EXPECT_EQ((std::vector<float>{16, 9, 4, 1, 0, 1}),
            squaredDistanceTransform(sources(6, 1, {{4, 0}}), 6, 1));
  // 1 x 6, source at y = 1.
  EXPECT_EQ((std::vector<float>{1, 0, 1, 4, 9, 16}),
            squaredDistanceTransform(sources(1, 6, {{0, 1}}), 1, 6));
  EXPECT_EQ((std::vector<float>{0}), squaredDistanceTransform({true}, 1, 1));
  EXPECT_EQ((std::vector<float>{kInf}), squaredDistanceTransform({false}, 1, 1));
}

TEST(SquaredDistanceTransform, SourceOnlyInOneColumnReachesTheWholeGrid) {
  // Columns without any source must still get distances through the row pass.
  // 4 x 3, source at (3, 2): (x - 3)^2 + (y - 2)^2.
  const std::vector<float> expected = {
      13, 8, 5, 4,  // y = 0
      10, 5, 2, 1,  // y = 1
      9,  4, 1, 0,  // y = 2
  };
  EXPECT_EQ(expected, squaredDistanceTransform(sources(4, 3, {{3, 2}}), 4, 3));
}

TEST(SquaredDistanceTransform, EmptyGridsGiveNothing) {
  EXPECT_TRUE(squaredDistanceTransform({}, 0, 0).empty());
  EXPECT_TRUE(squaredDistanceTransform({}, 5, 0).empty());
  EXPECT_TRUE(squaredDistanceTransform({}, 0, 5).empty());
}

TEST(SquaredDistanceTransform, MatchesBruteForceOnRandomGrids) {
  std::mt19937 rng(1234);
  const int width = 30, height = 20;
  // Dense, sparse, and a single source: the last two give large distances
  // next to cells the passes treat as "no source".
  for (double density : {0.3, 0.1, 0.02, 0.003}) {
    std::bernoulli_distribution is_source(density);
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<bool> grid(width * height);
      for (std::size_t i = 0; i < grid.size(); ++i) grid[i] = is_source(rng);
      const std::vector<float> expected = bruteForce(grid, width, height);
      const std::vector<float> actual = squaredDistanceTransform(grid, width, height);
      ASSERT_EQ(expected.size(), actual.size());
      for (std::size_t i = 0; i < expected.size(); ++i) {
        ASSERT_EQ(expected[i], actual[i])
            << "cell (" << i % width << ", " << i / width << "), density " << density;
      }
    }
  }
}

TEST(SquaredDistanceTransform, FarCornersOfALargerGridAreExact) {
  // 400 x 300 with one source in a corner: the far corner is 399^2 + 299^2.
  const int width = 400, height = 300;
  const std::vector<float> d =
      squaredDistanceTransform(sources(width, height, {{0, 0}}), width, height);
  EXPECT_EQ(0.0f, d[0]);
  EXPECT_EQ(399.0f * 399.0f + 299.0f * 299.0f, d.back());
  EXPECT_EQ(399.0f * 399.0f, d[width - 1]);
  EXPECT_EQ(299.0f * 299.0f, d[(height - 1) * width]);
  EXPECT_EQ(123.0f * 123.0f + 77.0f * 77.0f, d[77 * width + 123]);
}

// The capped passes on a whole grid: -1 where nothing is nearer than `cap` cells.
std::vector<int32_t> cappedTransform(const std::vector<bool>& grid, int width, int height,
                                     uint16_t cap) {
  std::vector<uint16_t> column(grid.size());
  const std::vector<uint8_t> flags(grid.begin(), grid.end());
  // In two slices of columns, as two threads would.
  const auto is_source = [](uint8_t flag) { return flag != 0; };
  cappedColumnDistances(flags.data(), is_source, width, height, cap, 0, width / 3, column.data());
  cappedColumnDistances(flags.data(), is_source, width, height, cap, width / 3, width,
                        column.data());
  std::vector<int32_t> out(grid.size());
  RowPassScratch scratch;
  for (int y = 0; y < height; ++y) {
    cappedRowPass(&column[static_cast<std::size_t>(y) * width], width, cap, &scratch,
                  &out[y * width]);
  }
  return out;
}

TEST(CappedDistanceTransform, ExactBelowTheCapOnRandomGrids) {
  std::mt19937 rng(99);
  const int width = 31, height = 23;
  for (uint16_t cap : {1, 2, 5, 40}) {
    for (double density : {0.3, 0.05, 0.003}) {
      std::bernoulli_distribution is_source(density);
      for (int trial = 0; trial < 4; ++trial) {
        std::vector<bool> grid(width * height);
        for (std::size_t i = 0; i < grid.size(); ++i) grid[i] = is_source(rng);
        const std::vector<float> exact = bruteForce(grid, width, height);
        const std::vector<int32_t> capped = cappedTransform(grid, width, height, cap);
        for (std::size_t i = 0; i < grid.size(); ++i) {
          // Below cap^2 the value itself; at or past it, -1 or any value
          // at least cap^2 (a source in reach, another out of it).
          const std::string at = "cell (" + std::to_string(i % width) + ", " +
                                 std::to_string(i / width) + "), cap " + std::to_string(cap);
          if (exact[i] < static_cast<float>(cap) * cap) {
            ASSERT_EQ(static_cast<int32_t>(exact[i]), capped[i]) << at;
          } else {
            ASSERT_TRUE(capped[i] == -1 || capped[i] >= int32_t{cap} * cap) << at;
          }
        }
      }
    }
  }
}

TEST(CappedDistanceTransform, NoSourceInReachIsMinusOne) {
  const std::vector<int32_t> d = cappedTransform(sources(9, 1, {{0, 0}}), 9, 1, 3);
  EXPECT_EQ((std::vector<int32_t>{0, 1, 4, -1, -1, -1, -1, -1, -1}), d);  // 3 columns: out of reach
  const std::vector<int32_t> none = cappedTransform(sources(3, 9, {{0, 0}}), 3, 9, 3);
  EXPECT_EQ(0, none[0]);
  EXPECT_EQ(4, none[2 * 3]);
  EXPECT_EQ(-1, none[3 * 3]);  // three rows up: out of the column pass's reach
  EXPECT_EQ(-1, none[8 * 3 + 2]);
}

}  // namespace
}  // namespace pf
