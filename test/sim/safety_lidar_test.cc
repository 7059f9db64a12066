#include "pf_localization/sim/safety_lidar.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace pf::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

SafetyLidarParams noiseless() {
  SafetyLidarParams p;
  p.sigma = 0.0;
  p.dropout_near = p.dropout_far = 0.0;
  p.short_rate = 0.0;
  return p;
}

TEST(SafetyLidarReadingsTest, NoReturnIsInfinityAndTooCloseIsRangeMin) {
  SimRandom random(1);
  const auto r =
      safetyLidarReadings({1.2344, kInf, 20.0, 19.9996, 0.01, 19.9994, 0.05}, noiseless(), &random);
  ASSERT_EQ(r.size(), 7u);
  EXPECT_FLOAT_EQ(r[0], 1.234f);
  EXPECT_EQ(r[1], std::numeric_limits<float>::infinity());  // nothing there
  EXPECT_EQ(r[2], std::numeric_limits<float>::infinity());  // at range_max
  EXPECT_EQ(r[3], std::numeric_limits<float>::infinity());  // rounds up to it
  EXPECT_EQ(r[4], 0.05f);                                   // nearer than range_min
  EXPECT_FLOAT_EQ(r[5], 19.999f);
  EXPECT_EQ(r[6], 0.05f);
}

TEST(SafetyLidarReadingsTest, NoiseIsCentimetreLevelGaussian) {
  SafetyLidarParams p = noiseless();
  p.sigma = 0.01;
  SimRandom random(2);
  const auto r = safetyLidarReadings(std::vector<double>(50000, 3.0), p, &random);
  double sum = 0.0, sq = 0.0;
  int beyond_3_sigma = 0;
  for (float v : r) {
    sum += v - 3.0;
    sq += (v - 3.0) * (v - 3.0);
    beyond_3_sigma += std::abs(v - 3.0) > 0.0305;  // 3 sigma and the 1 mm rounding
  }
  EXPECT_NEAR(sum / r.size(), 0.0, 2e-4);
  EXPECT_NEAR(std::sqrt(sq / r.size()), 0.01, 4e-4);
  EXPECT_LT(beyond_3_sigma, 0.004 * r.size());
}

TEST(SafetyLidarReadingsTest, FewDropoutsMoreOfThemFarAway) {
  const SafetyLidarParams p;  // the defaults, noise and all
  SimRandom random(3);
  const auto dropped = [&](double range) {
    const auto r = safetyLidarReadings(std::vector<double>(100000, range), p, &random);
    int n = 0;
    for (float v : r) n += std::isinf(v);
    return n / 100000.0;
  };
  EXPECT_NEAR(dropped(1.0), 0.002 + 0.028 * 0.0025, 0.001);
  EXPECT_NEAR(dropped(15.0), 0.002 + 0.028 * 0.5625, 0.003);
  EXPECT_LT(dropped(1.0), 0.005);
}

TEST(SafetyLidarReadingsTest, ABeamsNoiseDoesNotDependOnWhatTheOthersSee) {
  const SafetyLidarParams p;
  SimRandom a(4), b(4);
  std::vector<double> ideal(541, 4.0), other = ideal;
  for (int i = 0; i < 270; ++i) other[i] = kInf;  // half the view gone
  const auto ra = safetyLidarReadings(ideal, p, &a);
  const auto rb = safetyLidarReadings(other, p, &b);
  for (int i = 270; i < 541; ++i) EXPECT_EQ(ra[i], rb[i]) << i;
}

}  // namespace
}  // namespace pf::sim
