#include "pf_localization/core/map/bicubic_distance_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace pf {
namespace {

// 10 x 5 cells of 0.1 m whose column 0 is a wall: the distance at column i
// is 0.1 i, a linear ramp in x, the same in every row.
OccupancyGrid wallOnTheLeft(const Pose2& origin = {}) {
  std::vector<int8_t> data(50, 0);
  for (int y = 0; y < 5; ++y) data[y * 10] = 100;
  return OccupancyGrid(10, 5, 0.1, origin, data);
}

TEST(BicubicDistanceField, PassesThroughTheCellCentres) {
  // One obstacle at cell (2, 2) of a 5 x 5 grid of 0.1 m cells.
  std::vector<int8_t> data(25, 0);
  data[2 * 5 + 2] = 100;
  const DistanceField field(OccupancyGrid(5, 5, 0.1, {}, data), 2.0);
  const BicubicDistanceField smooth(field);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 5; ++x) {
      const FieldSample s = smooth.sample((x + 0.5) * 0.1, (y + 0.5) * 0.1);
      EXPECT_NEAR(field.distance({x, y}), s.distance, 1e-6) << x << "," << y;
    }
  }
  // The obstacle's centre is a minimum: zero, and flat by symmetry.
  const FieldSample centre = smooth.sample(0.25, 0.25);
  EXPECT_NEAR(0.0, centre.distance, 1e-12);
  EXPECT_NEAR(0.0, centre.dx, 1e-12);
  EXPECT_NEAR(0.0, centre.dy, 1e-12);
}

TEST(BicubicDistanceField, ReproducesTheRampBesideAWall) {
  const DistanceField field(wallOnTheLeft(), 2.0);
  const BicubicDistanceField smooth(field);
  // x = 0.43 m is 3.8 cells from the wall's centre: the stencil (columns 2
  // to 5, rows 1 to 4) lies on the ramp, which the cubic reproduces exactly.
  const FieldSample s = smooth.sample(0.43, 0.27);
  EXPECT_NEAR(0.38, s.distance, 1e-6);
  EXPECT_NEAR(1.0, s.dx, 1e-6);
  EXPECT_NEAR(0.0, s.dy, 1e-6);
}

TEST(BicubicDistanceField, FollowsARotatedOrigin) {
  // The same grid turned a quarter left about (1, 0): the ramp runs along +y.
  const DistanceField field(wallOnTheLeft({1.0, 0.0, M_PI / 2}), 2.0);
  const BicubicDistanceField smooth(field);
  // Grid point (0.43, 0.27) is world (1 - 0.27, 0.43).
  const FieldSample s = smooth.sample(0.73, 0.43);
  EXPECT_NEAR(0.38, s.distance, 1e-6);
  EXPECT_NEAR(0.0, s.dx, 1e-6);
  EXPECT_NEAR(1.0, s.dy, 1e-6);
}

TEST(BicubicDistanceField, GradientIsTheDerivativeOfTheValue) {
  // Near a corner of two walls, where the field bends.
  std::vector<int8_t> data(36, 0);
  for (int i = 0; i < 6; ++i) data[i] = data[i * 6] = 100;
  const DistanceField field(OccupancyGrid(6, 6, 0.1, {0.2, -0.1, 0.3}, data), 2.0);
  const BicubicDistanceField smooth(field);
  const double h = 1e-6;
  for (const auto& p : {std::pair<double, double>{0.41, 0.17}, {0.33, 0.08}, {0.55, 0.29}}) {
    const FieldSample s = smooth.sample(p.first, p.second);
    const double dx = (smooth.sample(p.first + h, p.second).distance -
                       smooth.sample(p.first - h, p.second).distance) /
                      (2 * h);
    const double dy = (smooth.sample(p.first, p.second + h).distance -
                       smooth.sample(p.first, p.second - h).distance) /
                      (2 * h);
    EXPECT_NEAR(dx, s.dx, 1e-6);
    EXPECT_NEAR(dy, s.dy, 1e-6);
  }
}

TEST(BicubicDistanceField, FarOffTheMapIsMaxDistanceAndFlat) {
  const DistanceField field(wallOnTheLeft(), 1.5);
  const BicubicDistanceField smooth(field);
  for (const double x : {-50.0, 50.0, std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()}) {
    const FieldSample s = smooth.sample(x, 0.2);
    EXPECT_EQ(1.5, s.distance);
    EXPECT_EQ(0.0, s.dx);
    EXPECT_EQ(0.0, s.dy);
  }
}

// The samples of many points taken together are those taken one by one, to
// the bit: on maps wide and narrow (where every stencil reaches past an
// edge), turned or not, at points on the map, by its edges and off it, and
// for counts that are not a multiple of the four points of the fast path.
TEST(BicubicDistanceField, ManyPointsAtOnceAreTheSameBits) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> wall(0, 9);
  for (const int width : {1, 3, 4, 23}) {
    const int height = width == 23 ? 17 : width + 1;
    std::vector<int8_t> data(static_cast<std::size_t>(width) * height, 0);
    for (auto& v : data) v = wall(rng) == 0 ? 100 : 0;
    data[0] = 100;
    for (const Pose2& origin : {Pose2{}, Pose2{-0.3, 0.7, 0.4}}) {
      const DistanceField field(OccupancyGrid(width, height, 0.05, origin, data), 0.5);
      const BicubicDistanceField smooth(field);
      // From two cells beyond every edge, where the field ends.
      std::uniform_real_distribution<double> x(origin.x - 0.15, origin.x + 0.05 * width + 0.15);
      std::uniform_real_distribution<double> y(origin.y - 0.15, origin.y + 0.05 * height + 0.15);
      std::vector<double> wx, wy;
      for (int i = 0; i < 1003; ++i) {
        wx.push_back(x(rng));
        wy.push_back(y(rng));
      }
      wx[5] = std::numeric_limits<double>::quiet_NaN();
      wy[9] = std::numeric_limits<double>::infinity();
      wx[10] = origin.x;  // a cell's edge
      wy[10] = origin.y;
      for (const std::size_t n : {std::size_t{0}, std::size_t{3}, std::size_t{8}, wx.size()}) {
        std::vector<FieldSample> many(n);
        smooth.sample(wx.data(), wy.data(), n, many.data());
        for (std::size_t i = 0; i < n; ++i) {
          const FieldSample one = smooth.sample(wx[i], wy[i]);
          EXPECT_EQ(0, std::memcmp(&one, &many[i], sizeof(FieldSample)))
              << "width " << width << ", point " << i << " (" << wx[i] << ", " << wy[i]
              << "): " << one.distance << " " << one.dx << " " << one.dy << " one by one, "
              << many[i].distance << " " << many[i].dx << " " << many[i].dy << " together";
        }
      }
    }
  }
}

// Inside a thick obstacle the field is the surface distance, which
// DistanceField stores negated: both paths, one point at a time and four,
// read it as |v|, and pass through it at the cell centres.
TEST(BicubicDistanceField, InsideAThickObstacleBothPathsSampleTheSurfaceDistance) {
  // 23 x 17 cells of 0.05 m with a block 15 x 11 cells (x 4-18, y 3-13),
  // whose middle lies up to six cells deep.
  const int width = 23, height = 17;
  std::vector<int8_t> data(static_cast<std::size_t>(width) * height, 0);
  for (int y = 3; y <= 13; ++y) {
    for (int x = 4; x <= 18; ++x) data[y * width + x] = 100;
  }
  const DistanceField field(OccupancyGrid(width, height, 0.05, {}, data), 0.5);
  const BicubicDistanceField smooth(field);
  std::vector<double> wx, wy;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      wx.push_back((x + 0.5) * 0.05);
      wy.push_back((y + 0.5) * 0.05);
    }
  }
  std::vector<FieldSample> many(wx.size());
  smooth.sample(wx.data(), wy.data(), wx.size(), many.data());
  int deep = 0;
  for (std::size_t i = 0; i < wx.size(); ++i) {
    const FieldSample one = smooth.sample(wx[i], wy[i]);
    EXPECT_NEAR(field.surfaceDistance(i), one.distance, 1e-9) << wx[i] << ", " << wy[i];
    EXPECT_EQ(0, std::memcmp(&one, &many[i], sizeof(FieldSample))) << wx[i] << ", " << wy[i];
    if (field.surfaceDistance(i) > 0.0f && field.distance(i) == 0.0f) ++deep;
  }
  // Three to six cells deep, (x 6-16) x (y 5-11): one to four cells past
  // the surface less kFreeDepth.
  EXPECT_EQ(11 * 7, deep);
  EXPECT_NEAR(0.2, smooth.sample(11.5 * 0.05, 8.5 * 0.05).distance, 1e-6);  // six deep (a float)
}

}  // namespace
}  // namespace pf
