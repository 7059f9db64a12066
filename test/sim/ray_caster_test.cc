#include "pf_localization/sim/ray_caster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace pf::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// '#' occupied, '.' free, '?' unknown; the first row is the top (highest y).
OccupancyGrid gridFromRows(const std::vector<std::string>& rows, double resolution,
                           const Pose2& origin = {}) {
  const int height = rows.size(), width = rows[0].size();
  std::vector<int8_t> data(width * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const char c = rows[height - 1 - y][x];
      data[y * width + x] = c == '#' ? 100 : c == '.' ? 0 : -1;
    }
  }
  return OccupancyGrid(width, height, resolution, origin, data);
}

const std::vector<std::string> kRows = {
    "######",  // y 3
    "#..?..",  // y 2: an unknown cell, then open to the edge of the map
    "#....#",  // y 1
    "######",  // y 0
};

TEST(RayCasterTest, RangesToWallCellBoundaries) {
  const RayCaster caster(gridFromRows(kRows, 1.0));
  EXPECT_DOUBLE_EQ(caster.cast(1.5, 1.5, 0.0, 10.0), 3.5);
  EXPECT_DOUBLE_EQ(caster.cast(1.5, 1.5, M_PI, 10.0), 0.5);
  EXPECT_DOUBLE_EQ(caster.cast(1.5, 1.5, M_PI / 2, 10.0), 1.5);
  EXPECT_DOUBLE_EQ(caster.cast(1.5, 1.5, -M_PI / 2, 10.0), 0.5);
  EXPECT_DOUBLE_EQ(caster.cast(4.25, 1.5, 0.0, 10.0), 0.75);
}

TEST(RayCasterTest, DiagonalRayEntersTheFirstOccupiedCellItCrosses) {
  const RayCaster caster(gridFromRows(kRows, 1.0));
  // Direction (0.6, 0.8): crosses y = 2 at t = 0.625 (free), x = 2 at
  // t = 0.833 (free), then y = 3 at t = 1.875, into the top wall.
  EXPECT_NEAR(caster.cast(1.5, 1.5, std::atan2(0.8, 0.6), 10.0), 1.875, 1e-12);
}

TEST(RayCasterTest, MaxRangeIsInclusive) {
  const RayCaster caster(gridFromRows(kRows, 1.0));
  EXPECT_DOUBLE_EQ(caster.cast(1.5, 1.5, 0.0, 3.5), 3.5);
  EXPECT_EQ(caster.cast(1.5, 1.5, 0.0, 3.49), kInf);
}

TEST(RayCasterTest, UnknownCellsAreTransparentAndLeavingTheMapReturnsNothing) {
  const RayCaster caster(gridFromRows(kRows, 1.0));
  EXPECT_EQ(caster.cast(1.5, 2.5, 0.0, 10.0), kInf);
  EXPECT_DOUBLE_EQ(caster.cast(1.5, 2.5, M_PI, 10.0), 0.5);
}

TEST(RayCasterTest, RayFromInsideAWallOrOffTheMap) {
  const RayCaster caster(gridFromRows(kRows, 1.0));
  EXPECT_EQ(caster.cast(0.5, 0.5, 0.0, 10.0), 0.0);
  EXPECT_EQ(caster.cast(-1.0, 1.5, 0.0, 10.0), kInf);
}

TEST(RayCasterTest, HonoursResolutionAndOrigin) {
  const RayCaster scaled(gridFromRows(kRows, 0.5, {-1.0, 2.0, 0.0}));
  EXPECT_DOUBLE_EQ(scaled.cast(-0.25, 2.75, 0.0, 10.0), 1.75);
  // A grid turned by 90 degrees: its x axis points along world +y, so grid
  // point (1.5, 1.5) is world (10 - 1.5, 1.5) and grid heading 0 is world pi/2.
  const RayCaster turned(gridFromRows(kRows, 1.0, {10.0, 0.0, M_PI / 2}));
  EXPECT_NEAR(turned.cast(8.5, 1.5, M_PI / 2, 10.0), 3.5, 1e-12);
}

TEST(CastToCircleTest, HitsMissesAndInside) {
  EXPECT_DOUBLE_EQ(castToCircle(0.0, 0.0, 0.0, 3.0, 0.0, 1.0), 2.0);
  EXPECT_EQ(castToCircle(0.0, 0.0, M_PI / 2, 0.0, -5.0, 1.0), kInf);  // behind
  EXPECT_EQ(castToCircle(0.0, 0.0, 0.0, 3.0, 2.0, 1.0), kInf);        // passes by
  EXPECT_EQ(castToCircle(3.2, 0.0, 0.0, 3.0, 0.0, 1.0), kInf);        // inside
}

NeatoLaserParams noiseless() {
  NeatoLaserParams p;
  p.sigma = 0.0;
  p.dropout_near = p.dropout_far = 0.0;
  p.burst_rate = 0.0;
  p.short_rate = 0.0;
  p.blind_sectors.clear();
  return p;
}

TEST(NeatoReadingsTest, NoiselessReadingsAreRoundedToMillimetres) {
  SimRandom random(1);
  const auto r = neatoReadings({1.2344, kInf, 5.0, 4.9996, 0.01, 4.9994}, noiseless(), &random);
  ASSERT_EQ(r.size(), 6u);
  EXPECT_FLOAT_EQ(r[0], 1.234f);
  EXPECT_EQ(r[1], 0.0f);  // nothing within range
  EXPECT_EQ(r[2], 0.0f);  // at range_max
  EXPECT_EQ(r[3], 0.0f);  // rounds up to range_max
  EXPECT_EQ(r[4], 0.0f);  // below range_min
  EXPECT_FLOAT_EQ(r[5], 4.999f);
}

TEST(NeatoReadingsTest, DropoutRateGrowsWithRange) {
  NeatoLaserParams p = noiseless();
  p.dropout_near = 0.1;
  p.dropout_far = 0.5;
  SimRandom random(7);
  const auto fraction = [&](double range) {
    const auto r = neatoReadings(std::vector<double>(20000, range), p, &random);
    int dropped = 0;
    for (float v : r) dropped += v == 0.0f;
    return dropped / 20000.0;
  };
  EXPECT_NEAR(fraction(0.05), 0.10004, 0.01);
  EXPECT_NEAR(fraction(2.5), 0.2, 0.01);
  EXPECT_NEAR(fraction(4.5), 0.424, 0.01);
}

TEST(NeatoReadingsTest, BlindSectorsNeverReturnAndTheirEdgesSometimes) {
  NeatoLaserParams p = noiseless();
  p.blind_sectors = {{10, 12}};
  p.blind_edge = 0.5;
  SimRandom random(2);
  std::vector<int> valid(36, 0);
  for (int scan = 0; scan < 2000; ++scan) {
    const auto r = neatoReadings(std::vector<double>(36, 1.0), p, &random);  // 10 deg apart
    for (int i = 0; i < 36; ++i) valid[i] += r[i] != 0.0f;
  }
  EXPECT_EQ(valid[1], 0);  // 10 deg
  EXPECT_EQ(valid[0], 2000);
  EXPECT_EQ(valid[2], 2000);  // 20 deg: beyond the edge
  p.blind_sectors = {{20, 20}};
  std::vector<int> edge(360, 0);
  for (int scan = 0; scan < 2000; ++scan) {
    const auto r = neatoReadings(std::vector<double>(360, 1.0), p, &random);  // 1 deg apart
    for (int i = 0; i < 360; ++i) edge[i] += r[i] != 0.0f;
  }
  EXPECT_EQ(edge[20], 0);
  EXPECT_NEAR(edge[19], 1000, 80);
  EXPECT_NEAR(edge[21], 1000, 80);
  EXPECT_EQ(edge[18], 2000);
  EXPECT_EQ(edge[22], 2000);
}

TEST(NeatoReadingsTest, BurstsDropRunsOfBeams) {
  NeatoLaserParams p = noiseless();
  p.burst_rate = 0.02;
  p.burst_mean = 5.0;
  SimRandom random(3);
  const auto r = neatoReadings(std::vector<double>(100000, 1.0), p, &random);
  int runs = 0, dropped = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    dropped += r[i] == 0.0f;
    runs += r[i] == 0.0f && (i == 0 || r[i - 1] != 0.0f);
  }
  // Runs can merge when a burst starts right after another, so slightly longer.
  EXPECT_NEAR(static_cast<double>(dropped) / runs, 5.0, 0.3);
  // A burst starts on 2% of the beams not already in one: on average 49
  // kept beams, then 5 dropped.
  EXPECT_NEAR(dropped / 100000.0, 5.0 / 54.0, 0.01);
}

}  // namespace
}  // namespace pf::sim
