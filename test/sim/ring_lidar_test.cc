#include "pf_localization/sim/ring_lidar.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/sim/amr_rig.h"
#include "pf_localization/sim/building_clutter.h"
#include "pf_localization/sim/building_map.h"
#include "support/rooms.h"

namespace pf::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

RingLidar noiseless() {
  RingLidar l = amrRingLidar({100'000'000, 0});
  l.sigma = 0.0;
  l.dropout = 0.0;
  return l;
}

// A point of a sweep in the map frame, with base_link at `base`.
struct MapPoint {
  double x, y, z;
};
MapPoint toMap(const RingLidar& l, const Pose2& base, const RingPoint& p) {
  const Pose2 s = compose(base, l.mount);
  const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
  return {s.x + c * p.x - sn * p.y, s.y + sn * p.x + c * p.y, l.height + p.z};
}

TEST(RingLidarTest, SixteenRingsOf1800ColumnsInOrder) {
  const RingLidar l = noiseless();
  EXPECT_EQ(l.rings, 16);
  EXPECT_EQ(l.columns, 1800);
  EXPECT_NEAR(l.elevation(0), -15 * kDeg, 1e-12);
  EXPECT_NEAR(l.elevation(1), -13 * kDeg, 1e-12);
  EXPECT_NEAR(l.elevation(15), 15 * kDeg, 1e-12);
  EXPECT_NEAR(l.azimuth(1), 0.2 * kDeg, 1e-15);
  const Scene3D scene(test::tenMetreRoom(), 2.5, {}, {});
  SimRandom random(1);
  const auto points = ringSweep(l, scene, {5.0, 5.0, 0.3}, 0.0, &random);
  ASSERT_EQ(points.size(), 16u * 1800u);
  // Point (r, c) lies along ring r's elevation and column c's azimuth.
  for (int r = 0; r < l.rings; ++r) {
    for (int c = 0; c < l.columns; c += 7) {
      const RingPoint& p = points[r * l.columns + c];
      ASSERT_TRUE(std::isfinite(p.x)) << r << " " << c;
      EXPECT_NEAR(std::atan2(p.z, std::hypot(p.x, p.y)), l.elevation(r), 1e-6);
      EXPECT_NEAR(std::remainder(std::atan2(p.y, p.x) - l.azimuth(c), 2 * M_PI), 0.0, 1e-6);
    }
  }
}

TEST(RingLidarTest, PointsLieOnTheFloorTheCeilingAndTheWalls) {
  // A low ceiling (1.5 m), so that the upper rings meet it before the walls
  // 4-6 m away: ring 15 at 3.4 m, ring 13 at 4.6 m.
  const RingLidar l = noiseless();
  const Scene3D scene(test::tenMetreRoom(), 1.5, {}, {});
  SimRandom random(2);
  const Pose2 base{4.0, 6.0, 2.0};
  const auto points = ringSweep(l, scene, base, 0.0, &random);
  int floor = 0, ceiling = 0, wall = 0;
  for (const RingPoint& p : points) {
    ASSERT_FALSE(std::isnan(p.x));
    const MapPoint m = toMap(l, base, p);
    if (p.intensity == surfaceIntensity(Surface::kFloor)) {
      EXPECT_NEAR(m.z, 0.0, 1e-5);
      ++floor;
    } else if (p.intensity == surfaceIntensity(Surface::kCeiling)) {
      EXPECT_NEAR(m.z, 1.5, 1e-5);
      ++ceiling;
    } else {
      ASSERT_EQ(p.intensity, surfaceIntensity(Surface::kWall));
      const double to_wall = std::min(
          {std::abs(m.x - 0.05), std::abs(m.x - 9.95), std::abs(m.y - 0.05), std::abs(m.y - 9.95)});
      EXPECT_LT(to_wall, 1e-4) << m.x << " " << m.y << " " << m.z;
      EXPECT_GE(m.z, -1e-5);
      EXPECT_LE(m.z, 1.5 + 1e-5);
      ++wall;
    }
  }
  // Ring 0 meets the floor 2.2 m out, ring 2 (-11 deg) 3.1 m, ring 3 4.0 m.
  EXPECT_GE(floor, 3 * 1800);
  EXPECT_GE(ceiling, 3 * 1800);
  EXPECT_GE(wall, 6 * 1800);
}

TEST(RingLidarTest, NoReturnIsNaNAndTooCloseToo) {
  RingLidar l = noiseless();
  const Scene3D open(test::tenMetreRoom(false), kInf, {}, {});
  SimRandom random(3);
  const auto points = ringSweep(l, open, {5.0, 5.0, 0.0}, 0.0, &random);
  for (int r = 0; r < l.rings; ++r) {
    const RingPoint& p = points[r * l.columns];
    // Up into nothing; level (no ring is) and down onto the floor within 100 m.
    EXPECT_EQ(std::isnan(p.x) && std::isnan(p.y) && std::isnan(p.z), l.elevation(r) > 0.0) << r;
    if (std::isnan(p.x)) {
      EXPECT_EQ(p.intensity, 0.0f);
    }
  }
  // Ring 0 meets the floor 0.6 / sin 15 deg = 2.32 m away, ring 1 2.67 m.
  l.range_min = 2.5;
  const auto near = ringSweep(l, open, {5.0, 5.0, 0.0}, 0.0, &random);
  EXPECT_TRUE(std::isnan(near[0].x));
  EXPECT_FALSE(std::isnan(near[1 * l.columns].x));
}

TEST(RingLidarTest, NoiseIsAlongTheRayAndDropoutsAreFew) {
  const RingLidar l = amrRingLidar({100'000'000, 0});
  const Scene3D scene(test::tenMetreRoom(), 2.5, {}, {});
  SimRandom random(4);
  const auto points = ringSweep(l, scene, {5.0, 5.0, 0.0}, 0.0, &random);
  int nan = 0;
  double sq = 0.0;
  int floor = 0;
  for (int c = 0; c < l.columns; ++c) {
    const RingPoint& p = points[c];  // ring 0: the floor, 0.6 / sin 15 deg away
    if (std::isnan(p.x)) {
      ++nan;
      continue;
    }
    const double range = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    sq += std::pow(range - 0.6 / std::sin(15 * kDeg), 2);
    ++floor;
  }
  for (const RingPoint& p : points) nan += std::isnan(p.x);
  EXPECT_NEAR(std::sqrt(sq / floor), l.sigma, 0.002);
  EXPECT_LT(nan, 0.01 * points.size());
  EXPECT_GT(nan, 0);
}

TEST(RingLidarTest, TheBuildingsObjectsStandAtTheirHeights) {
  // In the lobby, looking east at the standing table (x 11.2-12.4, y
  // 4.2-5.0, top 1.0-1.04 m) 1.6 m away, with the pallet (0-0.15 m) behind.
  const OccupancyGrid map = makeBuildingMap();
  const RingLidar l = noiseless();
  const Scene3D scene(map, kBuildingCeiling, buildingClutter(), {});
  SimRandom random(5);
  const Pose2 base{9.6, 4.6, 0.0};
  const auto points = ringSweep(l, scene, base, 0.0, &random);
  int table_top = 0, legs = 0, floor = 0, ceiling = 0, in_band = 0;
  for (const RingPoint& p : points) {
    if (std::isnan(p.x)) continue;
    const MapPoint m = toMap(l, base, p);
    if (p.intensity == surfaceIntensity(Surface::kObject)) {
      if (m.z > 0.99 && m.z < 1.05 && m.x > 11.19 && m.x < 12.41) ++table_top;
      if (m.z > 0.3 && m.z < 0.9) ++legs;
    }
    floor += std::abs(m.z) < 1e-4;
    ceiling += std::abs(m.z - kBuildingCeiling) < 1e-4;
    if (m.z > 0.3 && m.z < 0.9) {
      ++in_band;
      EXPECT_NE(p.intensity, surfaceIntensity(Surface::kFloor));
      EXPECT_NE(p.intensity, surfaceIntensity(Surface::kCeiling));
    }
  }
  EXPECT_GT(table_top, 20);
  EXPECT_GT(legs, 0);  // the table's legs cross the band
  EXPECT_GT(floor, 3000);
  EXPECT_GT(ceiling, 0);
  EXPECT_GT(in_band, 3000);
}

}  // namespace
}  // namespace pf::sim
