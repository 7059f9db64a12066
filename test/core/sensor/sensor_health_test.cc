// SensorHealth: each sensor's rate, age and beams, and which one is missing.
#include "pf_localization/core/sensor/sensor_health.h"

#include <gtest/gtest.h>

namespace pf {
namespace {

TEST(SensorHealth, RatesAgesAndShares) {
  SensorHealth health({"front", "rear"});
  for (int i = 0; i < 50; ++i) health.observe(0, 0.08 * i, 541, 530, 0.9);  // 12.5 Hz
  for (int i = 0; i < 40; ++i) health.observe(1, 0.1 * i, 541, 520, 0.8);   // 10 Hz
  const std::vector<SensorStatus> s = health.status(4.0);
  ASSERT_EQ(2u, s.size());
  EXPECT_EQ("front", s[0].name);
  EXPECT_EQ(SensorState::kOk, s[0].state);
  EXPECT_NEAR(12.5, s[0].rate_hz, 0.01);
  EXPECT_NEAR(10.0, s[1].rate_hz, 0.01);
  EXPECT_NEAR(4.0 - 0.08 * 49, s[0].age_s, 1e-9);
  EXPECT_NEAR(530.0 / 541.0, s[0].valid_share, 1e-12);
  EXPECT_NEAR(0.8, s[1].fit_share, 1e-12);
  EXPECT_EQ("", health.missing(4.0));
}

TEST(SensorHealth, ASilentOrCoveredSensorIsNamedWithinTwoSeconds) {
  SensorHealth health({"front", "rear", "points"});
  for (int i = 0; i <= 10; ++i) {
    health.observe(0, 0.1 * i, 541, 530, 0.9);
    health.observe(1, 0.1 * i, 541, i < 5 ? 530 : 0, 0.9);  // covered from 0.5 s on
  }
  EXPECT_EQ(SensorState::kWaiting, health.status(1.0)[2].state);  // no cloud yet: not missing
  EXPECT_EQ(SensorState::kBlocked, health.status(1.0)[1].state);
  EXPECT_EQ("rear (blocked: 0 % of its beams read)", health.missing(1.0));
  // The front lidar's last scan was at 1.0 s: silent after kSilentAfter.
  EXPECT_EQ(SensorState::kOk, health.status(1.0 + kSilentAfter - 0.01)[0].state);
  EXPECT_EQ(SensorState::kSilent, health.status(1.0 + kSilentAfter + 0.01)[0].state);
  EXPECT_NE(std::string::npos, health.missing(3.5).find("front (silent 2.5 s)"));
  // A reading again: back to ok.
  health.observe(1, 1.1, 541, 530, 0.9);
  EXPECT_EQ(SensorState::kOk, health.status(1.2)[1].state);
}

}  // namespace
}  // namespace pf
