#include <gtest/gtest.h>

#include <cmath>

#include "pf_localization/core/util/fast_math.h"

namespace pf {
namespace {

// Every direction at 1e-4 rad steps, at ranges from millimetres to
// kilometres: the octant reduction must be exact at every boundary.
TEST(FastAtan2, MatchesTheLibraryWithinTheStatedError) {
  double worst = 0.0;
  for (double a = -M_PI; a <= M_PI; a += 1e-4) {
    for (double r : {1e-3, 1.0, 37.0, 1e4}) {
      const double y = r * std::sin(a), x = r * std::cos(a);
      worst = std::max(worst, std::fabs(fastAtan2(y, x) - std::atan2(y, x)));
    }
  }
  EXPECT_LT(worst, 1e-7);
}

TEST(FastAtan2, AxesDiagonalsAndSignedZeros) {
  for (double y : {-2.0, -1.0, -0.0, 0.0, 1.0, 2.0}) {
    for (double x : {-2.0, -1.0, -0.0, 0.0, 1.0, 2.0}) {
      if (y == 0.0 && x == 0.0) continue;
      EXPECT_NEAR(fastAtan2(y, x), std::atan2(y, x), 1e-7) << y << ", " << x;
      EXPECT_EQ(std::signbit(fastAtan2(y, x)), std::signbit(std::atan2(y, x))) << y << ", " << x;
    }
  }
  EXPECT_EQ(fastAtan2(0.0, 0.0), 0.0);
  EXPECT_NEAR(fastAtan2(0.0, -1.0), M_PI, 1e-15);
  EXPECT_NEAR(fastAtan2(-0.0, -1.0), -M_PI, 1e-15);
}

}  // namespace
}  // namespace pf
