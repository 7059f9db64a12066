#include "pf_localization/sim/scene_3d.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "support/rooms.h"

namespace pf::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDeg = M_PI / 180.0;

TEST(CastToBoxTest, EntersThroughTheNearestFace) {
  const Box3 box{2.0, -1.0, 0.0, 3.0, 1.0, 0.5};
  EXPECT_DOUBLE_EQ(castToBox(0.0, 0.0, 0.25, 1.0, 0.0, 0.0, box), 2.0);
  EXPECT_EQ(castToBox(0.0, 0.0, 0.6, 1.0, 0.0, 0.0, box), kInf);    // over it
  EXPECT_EQ(castToBox(0.0, 0.0, 0.25, -1.0, 0.0, 0.0, box), kInf);  // behind
  EXPECT_EQ(castToBox(2.5, 0.0, 0.25, 1.0, 0.0, 0.0, box), kInf);   // inside
  // Down onto its top: from (0, 0, 1.5) towards (2.5, 0, 0.5).
  const double len = std::hypot(2.5, 1.0);
  EXPECT_NEAR(castToBox(0.0, 0.0, 1.5, 2.5 / len, 0.0, -1.0 / len, box), len, 1e-12);
}

TEST(Scene3DTest, FloorCeilingAndWallsAtTheirHeights) {
  const Scene3D scene(test::tenMetreRoom(), 2.5, {}, {});
  // From the room's centre, 0.6 m up, looking along +x.
  const Hit floor = scene.cast(5.0, 5.0, 0.6, 0.0, -30 * kDeg, 100.0, 0.0);
  EXPECT_EQ(floor.surface, Surface::kFloor);
  EXPECT_NEAR(floor.range, 1.2, 1e-12);
  const Hit ceiling = scene.cast(5.0, 5.0, 0.6, 0.0, 30 * kDeg, 100.0, 0.0);
  EXPECT_EQ(ceiling.surface, Surface::kCeiling);
  EXPECT_NEAR(ceiling.range, 3.8, 1e-12);
  const Hit level = scene.cast(5.0, 5.0, 0.6, 0.0, 0.0, 100.0, 0.0);
  EXPECT_EQ(level.surface, Surface::kWall);
  EXPECT_NEAR(level.range, 4.95, 1e-9);
  // Slightly down: the floor is 6.86 m away horizontally, the wall 4.95 m,
  // which the ray meets 0.167 m above the floor.
  const Hit low = scene.cast(5.0, 5.0, 0.6, 0.0, -5 * kDeg, 100.0, 0.0);
  EXPECT_EQ(low.surface, Surface::kWall);
  EXPECT_NEAR(low.range, 4.95 / std::cos(5 * kDeg), 1e-9);
  // Steeply down towards a wall: the floor comes first.
  const Hit steep = scene.cast(9.0, 5.0, 0.6, 0.0, -45 * kDeg, 100.0, 0.0);
  EXPECT_EQ(steep.surface, Surface::kFloor);
  EXPECT_NEAR(steep.range, 0.6 * std::sqrt(2.0), 1e-12);
  // max_range is inclusive, and nothing within it is no hit.
  EXPECT_EQ(scene.cast(5.0, 5.0, 0.6, 0.0, 0.0, 4.95, 0.0).surface, Surface::kWall);
  const Hit short_range = scene.cast(5.0, 5.0, 0.6, 0.0, 0.0, 4.9, 0.0);
  EXPECT_EQ(short_range.surface, Surface::kNothing);
  EXPECT_EQ(short_range.range, kInf);
}

TEST(Scene3DTest, WithoutCeilingOrWallsARayUpFindsNothing) {
  const Scene3D scene(test::tenMetreRoom(false), kInf, {}, {});
  EXPECT_EQ(scene.cast(5.0, 5.0, 0.6, 0.0, 10 * kDeg, 100.0, 0.0).surface, Surface::kNothing);
  EXPECT_EQ(scene.cast(5.0, 5.0, 0.6, 0.0, -10 * kDeg, 100.0, 0.0).surface, Surface::kFloor);
}

TEST(Scene3DTest, ObjectsAreSeenAtTheirHeightsOnly) {
  const Box3 parcel{6.0, 4.8, 0.0, 6.5, 5.2, 0.2};
  const Box3 table_top{7.0, 4.0, 1.0, 8.0, 6.0, 1.04};
  const Scene3D scene(test::tenMetreRoom(), 2.5, {parcel, table_top}, {});
  // A level ray at 0.6 m passes over the parcel and under the table.
  EXPECT_EQ(scene.cast(5.0, 5.0, 0.6, 0.0, 0.0, 100.0, 0.0).surface, Surface::kWall);
  // Aimed at the middle of the parcel's top.
  const double down = std::atan2(0.4, 1.25);
  const Hit parcel_hit = scene.cast(5.0, 5.0, 0.6, 0.0, -down, 100.0, 0.0);
  EXPECT_EQ(parcel_hit.surface, Surface::kObject);
  EXPECT_NEAR(parcel_hit.range, std::hypot(1.25, 0.4), 1e-12);
  // Aimed up at the table top's edge face (x = 7, z = 1.02).
  const double up = std::atan2(0.42, 2.0);
  const Hit table_hit = scene.cast(5.0, 5.0, 0.6, 0.0, up, 100.0, 0.0);
  EXPECT_EQ(table_hit.surface, Surface::kObject);
  EXPECT_NEAR(table_hit.range, std::hypot(2.0, 0.42), 1e-12);
}

TEST(Scene3DTest, PeopleAreUprightCylindersThatMove) {
  Person p;
  p.x1 = 7.0, p.y1 = 5.0, p.x2 = 7.0, p.y2 = 8.0, p.speed = 1.0;
  const Scene3D scene(test::tenMetreRoom(), 2.5, {}, {p}, 1.7);
  const Hit hit = scene.cast(5.0, 5.0, 0.6, 0.0, 0.0, 100.0, 0.0);
  EXPECT_EQ(hit.surface, Surface::kPerson);
  EXPECT_NEAR(hit.range, 1.8, 1e-12);
  // Over the head: at 1.8 m the ray is at 0.6 + 1.8 tan(40) = 2.11 m.
  EXPECT_EQ(scene.cast(5.0, 5.0, 0.6, 0.0, 40 * kDeg, 100.0, 0.0).surface, Surface::kCeiling);
  // Two seconds later the person has walked 2 m away.
  EXPECT_EQ(scene.cast(5.0, 5.0, 0.6, 0.0, 0.0, 100.0, 2.0).surface, Surface::kWall);
}

}  // namespace
}  // namespace pf::sim
